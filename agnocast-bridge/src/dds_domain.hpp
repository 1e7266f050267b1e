// The bridge's Cyclone DDS participant and the topics, writers and readers it
// makes for bridged topics, with the QoS of each topic mapped onto DDS.
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "config.hpp"

struct ddsi_sertype;

namespace agnocast_bridge {

// Cyclone DDS refused something: the domain did not start, or an entity failed.
class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Owns one DDS entity handle and deletes it (and its children) at the end.
class DdsEntity {
 public:
  DdsEntity() = default;
  explicit DdsEntity(dds_entity_t handle) : handle_(handle) {}
  ~DdsEntity() { reset(); }
  DdsEntity(DdsEntity&& other) noexcept : handle_(other.handle_) { other.handle_ = 0; }
  DdsEntity& operator=(DdsEntity&& other) noexcept;
  DdsEntity(const DdsEntity&) = delete;
  DdsEntity& operator=(const DdsEntity&) = delete;

  dds_entity_t get() const { return handle_; }
  void reset();

 private:
  dds_entity_t handle_ = 0;
};

struct DdsTopic {
  DdsEntity entity;
  // The topic's type (Cyclone's, if it had an equal one already), for the
  // serdata written; valid while the topic exists.
  const ddsi_sertype* sertype = nullptr;
};

class DdsDomain {
 public:
  // Throws DdsError naming the domain and Cyclone's reason when it cannot start
  // (a bad CYCLONEDDS_URI, no usable network interface, a domain id out of range).
  explicit DdsDomain(std::uint32_t domain_id);

  dds_entity_t participant() const { return participant_.get(); }
  std::uint32_t domain_id() const { return domain_id_; }

  // A ROS 2 compatible topic ("rt/...", "pkg::msg::dds_::Type_") of XCDR1 bytes.
  DdsTopic create_topic(const TopicConfig& topic);
  // A topic of XCDR1 bytes named as given ("rq/...Request", "pkg::srv::dds_::Name_Request_").
  DdsTopic create_topic(const std::string& dds_name, const std::string& dds_type);
  // user_data, when not empty, goes in the endpoint's USER_DATA QoS.
  DdsEntity create_writer(dds_entity_t topic, const TopicQos& qos,
                          const std::string& user_data = {});
  // Ignores the samples of this participant's own writers: a topic bridged both
  // ways does not read back what the bridge wrote.
  DdsEntity create_reader(dds_entity_t topic, const TopicQos& qos,
                          const std::string& user_data = {});
  // A new id for a service's (or a client's) reader and writer pair, as
  // rmw_cyclonedds_cpp makes them: the participant's GUID prefix and a counter.
  std::array<std::uint8_t, 16> new_service_endpoint_id();

 private:
  std::uint32_t domain_id_;
  DdsEntity participant_;
  std::uint32_t service_endpoints_ = 0;
};

// Throws DdsError with what, Cyclone's text for code, when code is negative.
dds_return_t check_dds(dds_return_t code, const std::string& what);

}  // namespace agnocast_bridge
