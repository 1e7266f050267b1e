#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/limits.hpp"
#include "endpoints/endpoint_request.hpp"
#include "endpoints/node_state.hpp"
#include "endpoints/notification_queue.hpp"
#include "kernel/runtime.hpp"
#include "log_internal.hpp"
#include "tracing/trace.hpp"

namespace agnocast::detail {

struct PublisherCore::State {
  State(std::shared_ptr<NodeState> node, Runtime& runtime, const EndpointRequest& request)
      : node(std::move(node)),
        runtime(runtime),
        topic(request.topic),
        endpoint(runtime.kernel().add_publisher(request)),
        senders(request.topic) {}

  std::shared_ptr<NodeState> node;
  Runtime& runtime;
  const std::string topic;
  const EndpointId endpoint;
  std::mutex mutex;  // one PUBLISH and its wake-ups at a time
  std::vector<std::uint32_t> wake_ids = std::vector<std::uint32_t>(16);
  QueueSenders senders;
};

PublisherCore::PublisherCore(std::shared_ptr<NodeState> node, std::string_view topic,
                             const QoS& qos, const MessageType& type, TopicUse use) {
  const EndpointRequest request =
      make_endpoint_request(node->name, topic, qos, EndpointKind::publisher, type, use);
  state_ = std::make_unique<State>(std::move(node), Runtime::get(), request);
  AGNOCAST_TRACE_INIT(this,
                      [publisher = this, node = state_->node.get(), topic = state_->topic.c_str(),
                       depth = qos.depth(), id = state_->endpoint.id] {
                        AGNOCAST_TRACE(agnocast_publisher_init, publisher, node, topic, depth, id);
                      });
}

PublisherCore::~PublisherCore() {
  AGNOCAST_FORGET_INIT(this);
  // In a fork child the endpoint is the parent's: leave it alone.
  if (Runtime::current() != &state_->runtime) return;
  try {
    state_->runtime.kernel().remove_publisher(state_->endpoint);
    state_->runtime.reclaim_all();
  } catch (const Error& error) {
    // Destructors cannot throw; the kernel drops everything at process exit.
    log(LogLevel::warning,
        std::string("removing a publisher of ") + state_->topic + ": " + error.what());
  }
}

const std::string& PublisherCore::topic() const { return state_->topic; }
std::uint32_t PublisherCore::id() const { return state_->endpoint.id; }

std::size_t PublisherCore::subscription_count() const {
  TopicInfo info;
  if (!state_->runtime.kernel().topic_info(state_->topic, info)) return 0;
  return info.subscribers.size();
}

bool PublisherCore::wait_for_subscribers(std::size_t count,
                                         std::chrono::nanoseconds timeout) const {
  // Nothing wakes a publisher when a subscriber joins: poll, often enough for
  // start-up ordering and cheap next to a process start.
  constexpr auto interval = std::chrono::milliseconds{5};
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (subscription_count() >= count) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) return false;
    std::this_thread::sleep_for(std::min<std::chrono::nanoseconds>(interval, deadline - now));
  }
}

void PublisherCore::publish(void* message, std::size_t bytes) { publish(message, bytes, {}); }

void PublisherCore::publish(void* message, std::size_t bytes, const ServiceRoute& route) {
  // The message is complete: what publishing allocates is the library's own.
  close_loan_heap_scope(message);
  State& state = *state_;
  if (Runtime::current() != &state.runtime) {
    throw Error(
        "agnocast: this publisher was created by the parent process before fork(); "
        "create publishers in the process that uses them");
  }
  std::array<std::uint64_t, 64> reclaimed;
  PublishResult result;
  stamp_publication(message, bytes);
  {
    std::lock_guard lock(state.mutex);
    for (;;) {
      try {
        result = state.runtime.kernel().publish(state.endpoint,
                                                reinterpret_cast<std::uintptr_t>(message), bytes,
                                                state.wake_ids, reclaimed, route);
        break;
      } catch (const DeviceError& error) {
        if (error.code() == ENOBUFS && state.wake_ids.size() < subscribers_per_topic_max) {
          state.wake_ids.resize(state.wake_ids.size() * 2);
          continue;
        }
        discard_message(message);
        throw;
      }
    }
    // Before the wake-ups: a subscriber's take never precedes its publish.
    AGNOCAST_TRACE(agnocast_publish, this, static_cast<std::int64_t>(result.entry_id),
                   state.topic.c_str(), state.endpoint.id);
    for (std::uint32_t i = 0; i < result.wake_count; ++i) {
      if (!state.senders.notify(state.wake_ids[i])) {
        state.runtime.kernel().notify_failed(state.endpoint, state.wake_ids[i]);
      }
    }
  }
  // Freed at the next borrow: the subscribers run first.
  state.runtime.defer_free(std::span(reclaimed.data(), result.reclaim_count));
  if (result.reclaim_pending > 0) state.runtime.reclaim_all();
}

}  // namespace agnocast::detail
