// One bridged topic in one direction, for message type T.
//   ToDds:   an agnocast subscription; each message is serialized once to
//            XCDR1 and written with dds_writecdr. It ignores the bridge's own
//            publications (ignore_local_publications: the kernel never queues
//            them for it), which are the messages FromDds relayed from DDS,
//            so that a topic bridged both ways does not send them back.
//   FromDds: a DDS reader; each sample's bytes are deserialized straight into
//            a loaned agnocast message, which is then published.
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <vector>

#include "agnocast/cdr.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/node.hpp"
#include "agnocast/subscription_options.hpp"
#include "cdr_sertype.hpp"
#include "config.hpp"
#include "dds_domain.hpp"
#include "topic_counters.hpp"

namespace agnocast_bridge {

class Relay {
 public:
  virtual ~Relay() = default;
  // FromDds: the reader to wait on; 0 for ToDds, which its executor drives.
  virtual dds_entity_t reader() const { return 0; }
  // FromDds: relays every sample waiting now.
  virtual void relay_available() {}
  // The agnocast subscription's id (ToDds), for its drop count in the kernel.
  virtual std::uint32_t subscription_id() const { return 0; }
};

// What a relay needs from the bridge: where it is, and where it counts.
struct RelayContext {
  const TopicConfig& topic;
  agnocast::Node& node;
  DdsDomain& domain;
  TopicCounters& counters;
};

// Takes every sample waiting on reader and hands each valid one's bytes to
// handle; a failed take counts as an error.
template <class Handle>
void take_cdr_samples(dds_entity_t reader, TopicCounters& counters, Handle&& handle) {
  constexpr std::uint32_t batch = 16;
  std::array<ddsi_serdata*, batch> samples{};
  std::array<dds_sample_info_t, batch> infos{};
  for (;;) {
    const dds_return_t taken =
        dds_takecdr(reader, samples.data(), batch, infos.data(), DDS_ANY_STATE);
    if (taken <= 0) {
      if (taken < 0) ++counters.errors;
      return;
    }
    for (dds_return_t i = 0; i < taken; ++i) {
      if (infos[i].valid_data) handle(cdr_serdata_bytes(samples[i]));
      release_serdata(samples[i]);
    }
  }
}

template <class T>
class ToDds : public Relay {
 public:
  explicit ToDds(const RelayContext& context)
      : counters_(context.counters),
        dds_topic_(context.domain.create_topic(context.topic)),
        writer_(context.domain.create_writer(dds_topic_.entity.get(), context.topic.qos)) {
    agnocast::QoS qos(context.topic.qos.depth);
    if (context.topic.qos.transient_local) qos.transient_local();
    agnocast::SubscriptionOptions options;
    options.ignore_local_publications = true;
    subscription_ = context.node.create_subscription<T>(
        context.topic.name, qos,
        [this](const agnocast::ipc_shared_ptr<const T>& message) { relay(*message); }, options);
  }

  std::uint32_t subscription_id() const override { return subscription_->id(); }

 private:
  void relay(const T& message) {
    std::vector<std::uint8_t> bytes;
    try {
      bytes = agnocast::cdr::serialize(message);
    } catch (const agnocast::cdr::Error&) {
      ++counters_.errors;
      return;
    }
    const dds_return_t written =
        dds_writecdr(writer_.get(), make_cdr_serdata(dds_topic_.sertype, std::move(bytes)));
    if (written == DDS_RETCODE_OK) {
      ++counters_.relayed;
    } else if (written == DDS_RETCODE_TIMEOUT) {
      ++counters_.dropped;
    } else {
      ++counters_.errors;
    }
  }

  TopicCounters& counters_;
  DdsTopic dds_topic_;
  DdsEntity writer_;
  std::shared_ptr<agnocast::Subscription<T>> subscription_;
};

template <class T>
class FromDds : public Relay {
 public:
  explicit FromDds(const RelayContext& context)
      : counters_(context.counters),
        dds_topic_(context.domain.create_topic(context.topic)),
        reader_(context.domain.create_reader(dds_topic_.entity.get(), context.topic.qos)) {
    agnocast::QoS qos(context.topic.qos.depth);
    if (context.topic.qos.transient_local) qos.transient_local();
    publisher_ = context.node.create_publisher<T>(context.topic.name, qos);
    check_dds(dds_set_status_mask(reader_.get(), DDS_DATA_AVAILABLE_STATUS), "DDS reader status");
  }

  dds_entity_t reader() const override { return reader_.get(); }

  void relay_available() override {
    take_cdr_samples(reader_.get(), counters_,
                     [this](std::span<const std::uint8_t> bytes) { relay(bytes); });
  }

 private:
  void relay(std::span<const std::uint8_t> bytes) {
    try {
      auto message = publisher_->borrow_loaned_message();
      agnocast::cdr::deserialize(bytes, *message);
      publisher_->publish(std::move(message));
      ++counters_.relayed;
    } catch (const agnocast::cdr::Error&) {
      ++counters_.errors;
    } catch (const std::bad_alloc&) {  // agnocast::PoolExhausted: no room for it
      ++counters_.dropped;
    } catch (const agnocast::Error&) {
      ++counters_.errors;
    }
  }

  TopicCounters& counters_;
  DdsTopic dds_topic_;
  DdsEntity reader_;
  std::shared_ptr<agnocast::Publisher<T>> publisher_;
};

}  // namespace agnocast_bridge
