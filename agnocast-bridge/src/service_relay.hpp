// One bridged service of type Srv, carried on DDS as rmw_cyclonedds_cpp
// carries services (service_wire.hpp), so that ROS 2 nodes on that RMW call
// it or answer it. Requests and responses are converted as topics' messages
// are (agnocast/cdr.hpp), with the 16-byte request header around them.
//   ServiceToDds:   the agnocast service is served on DDS. A DDS reader of
//                   rq/<name>Request hands each request to an agnocast client
//                   of the name; its response goes out on rr/<name>Reply with
//                   the request's header, which is how the DDS client knows it.
//   ServiceFromDds: a DDS service is served in agnocast. The bridge is the
//                   name's agnocast server (deferred); each request goes out on
//                   rq/ with a header of the bridge's own, and the reply that
//                   comes back on rr/ with that header answers the agnocast
//                   client. A request made while no DDS server is matched
//                   waits for one; a request not answered within the
//                   timeout, waiting or sent, fails (Service::fail_request):
//                   nothing stays pending.
#pragma once

#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <span>
#include <vector>

#include "agnocast/cdr.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/limits.hpp"
#include "agnocast/node.hpp"
#include "agnocast/service.hpp"
#include "cdr_sertype.hpp"
#include "config.hpp"
#include "dds_domain.hpp"
#include "dds_names.hpp"
#include "relay.hpp"
#include "service_wire.hpp"
#include "topic_counters.hpp"

namespace agnocast_bridge {

// What a service relay needs from the bridge. Counters: relayed = calls
// answered, dropped = calls not answered (no reply in time, too many waiting, the
// agnocast side refused or had no server), errors = bytes that are not valid
// XCDR1 for the type, or a DDS error.
struct ServiceRelayContext {
  const ServiceConfig& service;
  agnocast::Node& node;
  DdsDomain& domain;
  TopicCounters& counters;
};

// DDS QoS of a service's readers and writers: ROS 2's services default
// (reliable, volatile), with room in the history for bursts of calls.
inline constexpr TopicQos dds_service_qos{.depth = 100, .reliable = true, .transient_local = false};

// The DDS side shared by both directions: the two topics, a reader of one
// and a writer of the other, with a USER_DATA id that pairs them.
struct DdsServiceEndpoints {
  DdsServiceEndpoints(DdsDomain& domain, const ServiceConfig& service, bool serving)
      : names(dds_service_type_names(service.type)),
        topics(dds_service_topic_names(service.name)),
        request_topic(domain.create_topic(topics.request, names.dds_request)),
        reply_topic(domain.create_topic(topics.reply, names.dds_response)),
        user_data(service_user_data(serving ? "serviceid" : "clientid",
                                    domain.new_service_endpoint_id())),
        reader(domain.create_reader(serving ? request_topic.entity.get() : reply_topic.entity.get(),
                                    dds_service_qos, user_data)),
        writer(domain.create_writer(serving ? reply_topic.entity.get() : request_topic.entity.get(),
                                    dds_service_qos, user_data)),
        written_type(serving ? reply_topic.sertype : request_topic.sertype) {
    check_dds(dds_set_status_mask(reader.get(), DDS_DATA_AVAILABLE_STATUS), "DDS reader status");
  }

  dds_return_t write(const DdsRequestHeader& header, std::vector<std::uint8_t>&& message) {
    return dds_writecdr(
        writer.get(),
        make_cdr_serdata(written_type, with_request_header(header, std::move(message))));
  }

  ServiceTypeNames names;
  DdsServiceTopics topics;
  DdsTopic request_topic;
  DdsTopic reply_topic;
  std::string user_data;
  DdsEntity reader;
  DdsEntity writer;
  const ddsi_sertype* written_type;
};

template <agnocast::ServiceType Srv>
class ServiceToDds : public Relay {
 public:
  using Request = typename Srv::Request;
  using Response = typename Srv::Response;

  explicit ServiceToDds(const ServiceRelayContext& context)
      : counters_(context.counters),
        dds_(context.domain, context.service, true),
        // As many calls in flight as the library lets a client have: DDS
        // callers are many clients behind one.
        client_(context.node.create_client<Srv>(context.service.name,
                                                agnocast::QoS(agnocast::qos_depth_max))) {}

  dds_entity_t reader() const override { return dds_.reader.get(); }

  void relay_available() override {
    take_cdr_samples(dds_.reader.get(), counters_,
                     [this](std::span<const std::uint8_t> bytes) { call(bytes); });
  }

 private:
  void call(std::span<const std::uint8_t> bytes) {
    auto split = split_request_header(bytes);
    if (!split) {
      ++counters_.errors;
      return;
    }
    try {
      auto request = client_->borrow_loaned_request();
      agnocast::cdr::deserialize(split->message, *request);
      client_->async_send_request(
          std::move(request),
          [this, header = split->header](typename agnocast::Client<Srv>::SharedFuture answer) {
            reply(header, answer);
          });
    } catch (const agnocast::cdr::Error&) {
      ++counters_.errors;
    } catch (const std::bad_alloc&) {  // agnocast::PoolExhausted
      ++counters_.dropped;
    } catch (const agnocast::Error&) {  // TooManyRequests
      ++counters_.dropped;
    }
  }

  // A DDS client has no way to hear of a failure: a call agnocast did not
  // answer gets no reply, as from a ROS 2 server that went away.
  void reply(const DdsRequestHeader& header,
             const typename agnocast::Client<Srv>::SharedFuture& answer) {
    std::vector<std::uint8_t> bytes;
    try {
      bytes = agnocast::cdr::serialize(*answer.get());
    } catch (const agnocast::cdr::Error&) {
      ++counters_.errors;
      return;
    } catch (const std::exception&) {  // ServiceUnavailable, RequestRejected
      ++counters_.dropped;
      return;
    }
    const dds_return_t written = dds_.write(header, std::move(bytes));
    if (written == DDS_RETCODE_OK) {
      ++counters_.relayed;
    } else if (written == DDS_RETCODE_TIMEOUT) {
      ++counters_.dropped;
    } else {
      ++counters_.errors;
    }
  }

  TopicCounters& counters_;
  DdsServiceEndpoints dds_;
  std::shared_ptr<agnocast::Client<Srv>> client_;
};

template <agnocast::ServiceType Srv>
class ServiceFromDds : public Relay {
 public:
  using Request = typename Srv::Request;
  using Response = typename Srv::Response;

  explicit ServiceFromDds(const ServiceRelayContext& context)
      : counters_(context.counters),
        timeout_(context.service.timeout),
        dds_(context.domain, context.service, false) {
    check_dds(dds_get_instance_handle(dds_.writer.get(), &client_id_), "DDS writer handle");
    service_ = context.node.create_service<Srv>(
        context.service.name,
        [this](std::shared_ptr<agnocast::Service<Srv>>, agnocast::RequestId id,
               agnocast::ipc_shared_ptr<const Request> request) { forward(id, *request); });
    // Often enough that a request fails within a tenth of its timeout (at
    // least 10 ms, at most 100 ms) after it, and that one waiting for a DDS
    // server goes out as soon after the match.
    sweeper_ = context.node.create_wall_timer(
        std::clamp<std::chrono::milliseconds>(timeout_ / 10, std::chrono::milliseconds(10),
                                              std::chrono::milliseconds(100)),
        [this] { sweep(); });
  }

  dds_entity_t reader() const override { return dds_.reader.get(); }

  void relay_available() override {
    take_cdr_samples(dds_.reader.get(), counters_,
                     [this](std::span<const std::uint8_t> bytes) { answer(bytes); });
  }

 private:
  struct Pending {
    agnocast::RequestId id;
    std::chrono::steady_clock::time_point deadline;
  };
  // A request not yet sent: no DDS server was matched when it came.  As many
  // wait as one agnocast client may have in flight; more fail at once.
  static constexpr std::size_t max_waiting = agnocast::qos_depth_max;
  struct Waiting {
    agnocast::RequestId id;
    std::chrono::steady_clock::time_point deadline;
    std::vector<std::uint8_t> bytes;
  };

  // On the executor's thread: the agnocast client's request goes to DDS.
  void forward(const agnocast::RequestId& id, const Request& request) {
    std::vector<std::uint8_t> bytes;
    try {
      bytes = agnocast::cdr::serialize(request);
    } catch (const agnocast::cdr::Error&) {
      ++counters_.errors;
      fail(id);
      return;
    }
    // Until discovery has matched a DDS server both ways, a request written
    // would reach nobody, or its reply would: it waits, behind any others.
    if (waiting_.size() == max_waiting) {
      ++counters_.dropped;
      fail(id);
      return;
    }
    waiting_.push_back({id, std::chrono::steady_clock::now() + timeout_, std::move(bytes)});
    send_waiting();
  }

  // A DDS server is matched when a reader takes our requests and a writer
  // can answer on our reply topic.
  bool server_matched() const {
    dds_publication_matched_status_t requests{};
    dds_subscription_matched_status_t replies{};
    return dds_get_publication_matched_status(dds_.writer.get(), &requests) == DDS_RETCODE_OK &&
           requests.current_count > 0 &&
           dds_get_subscription_matched_status(dds_.reader.get(), &replies) == DDS_RETCODE_OK &&
           replies.current_count > 0;
  }

  // On the executor's thread: a request goes out on DDS, pending its reply.
  void send(Waiting&& request) {
    std::int64_t sequence = 0;
    {
      std::lock_guard lock(mutex_);
      sequence = ++next_sequence_;
      pending_.emplace(sequence, Pending{request.id, request.deadline});
    }
    const dds_return_t written = dds_.write({client_id_, sequence}, std::move(request.bytes));
    if (written != DDS_RETCODE_OK) {
      ++(written == DDS_RETCODE_TIMEOUT ? counters_.dropped : counters_.errors);
      if (take_pending(sequence)) fail(request.id);
    }
  }

  // On the executor's thread: the requests that waited for a DDS server go
  // out, in the order they came, once one is matched.
  void send_waiting() {
    if (waiting_.empty() || !server_matched()) return;
    std::deque<Waiting> ready;
    ready.swap(waiting_);
    for (Waiting& request : ready) send(std::move(request));
  }

  // On the DDS receiver's thread: a reply; those to other clients are not ours.
  void answer(std::span<const std::uint8_t> bytes) {
    auto split = split_request_header(bytes);
    if (!split || split->header.client != client_id_) {
      if (!split) ++counters_.errors;
      return;
    }
    const std::optional<agnocast::RequestId> id = take_pending(split->header.sequence);
    if (!id) return;  // a reply after its request failed: nobody waits for it
    try {
      auto response = service_->borrow_loaned_response();
      agnocast::cdr::deserialize(split->message, *response);
      std::lock_guard lock(service_mutex_);
      service_->send_response(*id, std::move(response));
      ++counters_.relayed;
      return;
    } catch (const agnocast::cdr::Error&) {
      ++counters_.errors;
    } catch (const std::bad_alloc&) {  // agnocast::PoolExhausted
      ++counters_.dropped;
    } catch (const agnocast::Error&) {
      ++counters_.errors;
    }
    fail(*id);
  }

  // On the executor's thread: requests that waited for a DDS server go out
  // or, like those sent, fail when their time is up.
  void sweep() {
    send_waiting();
    const auto now = std::chrono::steady_clock::now();
    std::vector<agnocast::RequestId> expired;
    while (!waiting_.empty() && waiting_.front().deadline <= now) {
      expired.push_back(waiting_.front().id);
      waiting_.pop_front();
    }
    {
      std::lock_guard lock(mutex_);
      for (auto it = pending_.begin(); it != pending_.end();) {
        if (it->second.deadline > now) {
          ++it;
          continue;
        }
        expired.push_back(it->second.id);
        it = pending_.erase(it);
      }
    }
    for (const auto& id : expired) {
      ++counters_.dropped;
      fail(id);
    }
  }

  std::optional<agnocast::RequestId> take_pending(std::int64_t sequence) {
    std::lock_guard lock(mutex_);
    const auto it = pending_.find(sequence);
    if (it == pending_.end()) return std::nullopt;
    const agnocast::RequestId id = it->second.id;
    pending_.erase(it);
    return id;
  }

  void fail(const agnocast::RequestId& id) {
    try {
      std::lock_guard lock(service_mutex_);
      service_->fail_request(id);
    } catch (const std::exception&) {  // no pool memory for the word: the client waits on
      ++counters_.errors;
    }
  }

  TopicCounters& counters_;
  const std::chrono::milliseconds timeout_;
  DdsServiceEndpoints dds_;
  dds_instance_handle_t client_id_ = 0;
  std::mutex mutex_;  // guards next_sequence_ and pending_
  std::int64_t next_sequence_ = 0;
  std::map<std::int64_t, Pending> pending_;
  // Only the executor's thread touches it; deadlines in arrival order.
  std::deque<Waiting> waiting_;
  // The service answers from the executor's thread and the DDS receiver's.
  std::mutex service_mutex_;
  std::shared_ptr<agnocast::Service<Srv>> service_;
  std::shared_ptr<agnocast::Timer> sweeper_;
};

}  // namespace agnocast_bridge
