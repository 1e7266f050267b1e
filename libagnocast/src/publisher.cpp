#include <unistd.h>

#include <array>
#include <cerrno>
#include <mutex>
#include <vector>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/errors.hpp"
#include "endpoint_request.hpp"
#include "node_state.hpp"
#include "notification_queue.hpp"
#include "runtime.hpp"

namespace agnocast::detail {

namespace {
constexpr std::size_t subscribers_per_topic_max = 1024;
}

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
                             const QoS& qos, const MessageType& type) {
  const EndpointRequest request =
      make_endpoint_request(node->name, topic, qos, EndpointKind::publisher, type);
  state_ = std::make_unique<State>(std::move(node), Runtime::get(), request);
}

PublisherCore::~PublisherCore() {
  // In a fork child the endpoint is the parent's: leave it alone.
  if (Runtime::current() != &state_->runtime) return;
  try {
    state_->runtime.kernel().remove_publisher(state_->endpoint);
    state_->runtime.reclaim_all();
  } catch (const Error&) {
    // Destructors cannot report; the kernel drops everything at process exit.
  }
}

const std::string& PublisherCore::topic() const { return state_->topic; }
std::uint32_t PublisherCore::id() const { return state_->endpoint.id; }

void PublisherCore::publish(void* message, std::size_t bytes) {
  State& state = *state_;
  if (Runtime::current() != &state.runtime) {
    throw Error(
        "agnocast: this publisher was created by the parent process before fork(); "
        "create publishers in the process that uses them");
  }
  std::array<std::uint64_t, 64> reclaimed;
  PublishResult result;
  {
    std::lock_guard lock(state.mutex);
    for (;;) {
      try {
        result = state.runtime.kernel().publish(state.endpoint,
                                                reinterpret_cast<std::uintptr_t>(message), bytes,
                                                state.wake_ids, reclaimed);
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
    for (std::uint32_t i = 0; i < result.wake_count; ++i) state.senders.notify(state.wake_ids[i]);
  }
  state.runtime.free_reclaimed(std::span(reclaimed.data(), result.reclaim_count));
  if (result.reclaim_pending > 0) state.runtime.reclaim_all();
}

}  // namespace agnocast::detail
