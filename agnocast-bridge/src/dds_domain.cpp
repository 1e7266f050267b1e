#include "dds_domain.hpp"

#include <dds/ddsi/ddsi_sertype.h>

#include <cstring>
#include <memory>

#include "cdr_sertype.hpp"
#include "dds_names.hpp"

namespace agnocast_bridge {
namespace {

struct QosDeleter {
  void operator()(dds_qos_t* qos) const { dds_delete_qos(qos); }
};
using QosPointer = std::unique_ptr<dds_qos_t, QosDeleter>;

// How long a reliable writer may wait for room in its history before a write
// counts as dropped (the agnocast side then moves on to the next message).
constexpr dds_duration_t reliable_max_blocking = DDS_SECS(1);

QosPointer endpoint_qos(const TopicQos& topic_qos, const std::string& user_data) {
  QosPointer qos(dds_create_qos());
  if (!user_data.empty()) dds_qset_userdata(qos.get(), user_data.data(), user_data.size());
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, static_cast<int32_t>(topic_qos.depth));
  if (topic_qos.reliable) {
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, reliable_max_blocking);
  } else {
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
  }
  dds_qset_durability(qos.get(), topic_qos.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL
                                                           : DDS_DURABILITY_VOLATILE);
  // The bytes are what cdr.hpp writes: XCDR1, as ROS 2 over Cyclone DDS uses.
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos.get(), 1, &xcdr1);
  return qos;
}

}  // namespace

dds_return_t check_dds(dds_return_t code, const std::string& what) {
  if (code < 0) throw DdsError(what + ": " + dds_strretcode(code));
  return code;
}

DdsEntity& DdsEntity::operator=(DdsEntity&& other) noexcept {
  if (this != &other) {
    reset();
    handle_ = other.handle_;
    other.handle_ = 0;
  }
  return *this;
}

void DdsEntity::reset() {
  if (handle_ > 0) dds_delete(handle_);
  handle_ = 0;
}

DdsDomain::DdsDomain(std::uint32_t domain_id) : domain_id_(domain_id) {
  const dds_entity_t participant = dds_create_participant(domain_id, nullptr, nullptr);
  if (participant < 0) {
    throw DdsError("DDS domain " + std::to_string(domain_id) +
                   " cannot start: " + dds_strretcode(participant) +
                   " (Cyclone DDS logs why on stderr; check CYCLONEDDS_URI and the network "
                   "interfaces)");
  }
  participant_ = DdsEntity(participant);
}

DdsTopic DdsDomain::create_topic(const TopicConfig& topic) {
  return create_topic(dds_topic_name(topic.name), dds_type_name(topic.type));
}

DdsTopic DdsDomain::create_topic(const std::string& name, const std::string& dds_type) {
  ddsi_sertype* sertype = make_cdr_sertype(dds_type);
  const dds_entity_t handle =
      dds_create_topic_sertype(participant(), name.c_str(), &sertype, nullptr, nullptr, nullptr);
  if (handle < 0) {
    ddsi_sertype_unref(sertype);
    check_dds(handle, "DDS topic " + name);
  }
  return DdsTopic{DdsEntity(handle), sertype};
}

DdsEntity DdsDomain::create_writer(dds_entity_t topic, const TopicQos& topic_qos,
                                   const std::string& user_data) {
  const QosPointer qos = endpoint_qos(topic_qos, user_data);
  return DdsEntity(
      check_dds(dds_create_writer(participant(), topic, qos.get(), nullptr), "DDS writer"));
}

DdsEntity DdsDomain::create_reader(dds_entity_t topic, const TopicQos& topic_qos,
                                   const std::string& user_data) {
  const QosPointer qos = endpoint_qos(topic_qos, user_data);
  dds_qset_ignorelocal(qos.get(), DDS_IGNORELOCAL_PARTICIPANT);
  return DdsEntity(
      check_dds(dds_create_reader(participant(), topic, qos.get(), nullptr), "DDS reader"));
}

std::array<std::uint8_t, 16> DdsDomain::new_service_endpoint_id() {
  dds_guid_t guid{};
  check_dds(dds_get_guid(participant(), &guid), "DDS participant GUID");
  std::array<std::uint8_t, 16> id{};
  std::memcpy(id.data(), guid.v, 12);
  const std::uint32_t count = ++service_endpoints_;
  for (std::size_t i = 0; i < 4; ++i) id[12 + i] = static_cast<std::uint8_t>(count >> (24 - 8 * i));
  return id;
}

}  // namespace agnocast_bridge
