// The server side of a service: one callback subscriber on the request topic,
// one publisher on the reply topic that sends each response to the one
// client that asked.
#include <cerrno>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "agnocast/detail/service_cores.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"
#include "endpoints/node_state.hpp"
#include "kernel/runtime.hpp"
#include "log_internal.hpp"

namespace agnocast::detail {
namespace {

// Responses go to one client each, never to late subscribers: the publisher's
// window needs to keep none but the newest.
QoS reply_publisher_qos() { return QoS(1); }

std::string checked_request_topic(std::string_view service) {
  validate_service_name(service);
  return service_request_topic(service);
}

const PublisherInfo* find_publisher(const TopicInfo& info, std::uint32_t id) {
  for (const auto& publisher : info.publishers) {
    if (publisher.id == id) return &publisher;
  }
  return nullptr;
}

const SubscriberInfo* find_subscriber(const TopicInfo& info, std::uint32_t id) {
  for (const auto& subscriber : info.subscribers) {
    if (subscriber.id == id) return &subscriber;
  }
  return nullptr;
}

}  // namespace

struct ServiceCore::State {
  State(std::shared_ptr<NodeState> node, std::string_view service, const MessageType& response_type,
        ResponseFactory empty_response)
      : name(service),
        request_topic(service_request_topic(service)),
        replies(std::move(node), service_reply_topic(service), reply_publisher_qos(), response_type,
                TopicUse::service_carrier),
        empty_response(empty_response) {}

  const std::string name;
  const std::string request_topic;
  PublisherCore replies;
  const ResponseFactory empty_response;
  std::mutex mutex;
  // Request publisher id -> the reply subscriber id it names, once both are
  // seen to belong to one process: a caller cannot have responses sent to
  // another client. Holds live clients only (rebuilt whenever a new one asks).
  std::map<std::uint32_t, std::uint32_t> clients;
  std::uint64_t calls = 0;
  std::uint64_t failures = 0;
};

ServiceCore::ServiceCore(std::shared_ptr<NodeState> node, std::string_view service, const QoS& qos,
                         const MessageType& request_type, const MessageType& response_type,
                         ResponseFactory empty_response, const SubscriptionOptions& options)
    : SubscriptionBase(node, checked_request_topic(service), qos, request_type, options,
                       TopicUse::service_carrier) {
  state_ = std::make_unique<State>(std::move(node), service, response_type, empty_response);
  // One server per name: of two starting at once, the later reply publisher gives way.
  TopicInfo info;
  if (!Runtime::get().kernel().topic_info(state_->replies.topic(), info)) return;
  for (const auto& other : info.publishers) {
    if (other.id >= state_->replies.id()) continue;
    throw ServiceExists("agnocast: service " + state_->name + " has a server already: pid " +
                        std::to_string(other.pid) + " (node '" + other.node +
                        "'); one server per service name");
  }
}

ServiceCore::~ServiceCore() {
  if (!state_) return;
  // Published after this server stopped taking requests: every client fails
  // what it sent here and has not had answered.
  try {
    void* word = state_->empty_response();
    set_service_tag(word, ServiceTag{0, state_->replies.id(), 0,
                                     static_cast<std::uint16_t>(ServiceStatus::server_gone)});
    state_->replies.publish(word, 0);
  } catch (const std::exception& error) {
    log(LogLevel::warning,
        "agnocast: service " + state_->name + ": telling clients it stops failed: " + error.what());
  }
}

const std::string& ServiceCore::service_name() const { return state_->name; }

std::uint64_t ServiceCore::calls() const {
  std::lock_guard lock(state_->mutex);
  return state_->calls;
}

std::uint64_t ServiceCore::failures() const {
  std::lock_guard lock(state_->mutex);
  return state_->failures;
}

void ServiceCore::deliver(const void* message, EntryReference* reference, const MessageInfo& info) {
  const ServiceTag tag = read_service_tag(message);
  State& state = *state_;
  std::optional<std::uint32_t> client;
  {
    std::lock_guard lock(state.mutex);
    if (const auto known = state.clients.find(info.publisher_id); known != state.clients.end()) {
      if (known->second == tag.peer) {
        client = tag.peer;
        ++state.calls;
      }
    }
  }
  if (!client && tag.status == static_cast<std::uint16_t>(ServiceStatus::request)) {
    // A new client: its request publisher and the reply subscriber it names
    // must be one process's.
    TopicInfo requests;
    TopicInfo replies;
    Kernel& kernel = Runtime::get().kernel();
    if (kernel.topic_info(state.request_topic, requests) &&
        kernel.topic_info(state.replies.topic(), replies)) {
      const PublisherInfo* asking = find_publisher(requests, info.publisher_id);
      const SubscriberInfo* named = find_subscriber(replies, tag.peer);
      std::lock_guard lock(state.mutex);
      std::erase_if(state.clients, [&](const auto& entry) {
        return find_publisher(requests, entry.first) == nullptr;
      });
      if (asking && named && asking->pid == named->pid) {
        state.clients[info.publisher_id] = tag.peer;
        client = tag.peer;
        ++state.calls;
      }
    }
  }
  if (!client) {
    release(reference);
    std::lock_guard lock(state.mutex);
    ++state.failures;
    log(LogLevel::warning, "agnocast: service " + state.name + ": ignored a request of publisher " +
                               std::to_string(info.publisher_id) +
                               " that names no reply subscriber of its own process");
    return;
  }
  handle_request(message, reference, RequestId{*client, tag.sequence});
}

void ServiceCore::send_response(const RequestId& id, void* response, std::size_t bytes) {
  send_reply(id, response, bytes, ServiceStatus::response);
}

void ServiceCore::fail_request(const RequestId& id) {
  send_reply(id, state_->empty_response(), 0, ServiceStatus::failed);
}

void ServiceCore::send_reply(const RequestId& id, void* response, std::size_t bytes,
                             ServiceStatus status) {
  State& state = *state_;
  set_service_tag(
      response, ServiceTag{id.sequence, state.replies.id(), 0, static_cast<std::uint16_t>(status)});
  try {
    state.replies.publish(response, bytes, ServiceRoute{id.client, true});
  } catch (const DeviceError& error) {
    // ENXIO: the client is gone, and nothing waits for the response.
    if (error.code() != ENXIO && error.code() != EAGAIN) throw;
    std::lock_guard lock(state.mutex);
    ++state.failures;
    if (error.code() == EAGAIN) {
      log(LogLevel::warning, "agnocast: service " + state.name + ": client " +
                                 std::to_string(id.client) +
                                 " does not take its responses (its queue is full): dropped one");
    }
  }
}

}  // namespace agnocast::detail
