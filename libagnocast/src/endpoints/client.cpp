// The client side of a service: one publisher on the request topic that
// sends each request to the server's subscriber alone, refused rather than
// dropped; one callback subscriber on the reply topic that gets the responses
// to this client only. A server that goes away fails what it left pending:
// its process's exit is watched through a pidfd, and a server that stops
// tells its clients.
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "agnocast/detail/service_cores.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/limits.hpp"
#include "agnocast/naming.hpp"
#include "endpoints/node_state.hpp"
#include "kernel/runtime.hpp"
#include "log_internal.hpp"

namespace agnocast::detail {
namespace {

// Room for the responses of every request in flight, and as many again for
// those of requests pruned before their answer came.
QoS reply_queue_qos(const QoS& qos) {
  return QoS(std::min<std::size_t>(qos_depth_max, 2 * qos.depth() + 1));
}

std::string checked_reply_topic(std::string_view service) {
  validate_service_name(service);
  return service_reply_topic(service);
}

// The serving process: its publisher on the reply topic and its subscriber
// on the request topic.
struct Server {
  std::uint32_t reply_publisher = 0;
  pid_t pid = 0;
  std::uint32_t request_subscriber = 0;
};

int open_pidfd(pid_t pid) { return static_cast<int>(::syscall(SYS_pidfd_open, pid, 0)); }

}  // namespace

// Readable when the server's process has exited.
class ServerWatch : public Waitable {
 public:
  ServerWatch(std::shared_ptr<CallbackGroup> group, int pidfd,
              std::weak_ptr<ClientCore::State> client, std::uint32_t server)
      : Waitable(std::move(group)), pidfd_(pidfd), client_(std::move(client)), server_(server) {}
  ~ServerWatch() override { ::close(pidfd_); }

  int wait_fd() const override { return pidfd_; }
  void execute() override;

 private:
  int pidfd_;
  std::weak_ptr<ClientCore::State> client_;
  const std::uint32_t server_;
};

struct ClientCore::State : std::enable_shared_from_this<ClientCore::State> {
  State(std::shared_ptr<NodeState> node, std::string_view service, const QoS& qos,
        const MessageType& request_type, std::shared_ptr<CallbackGroup> group)
      : name(service),
        node(node),
        group(std::move(group)),
        bound(qos.depth()),
        requests(std::move(node), service_request_topic(service), QoS(1), request_type,
                 TopicUse::service_carrier) {}

  struct Pending {
    std::uint32_t server = 0;  // its reply publisher id
    Completion completion;
  };

  // The server to send to, found in the kernel's tables when there is none
  // yet, watched from then on; nullopt when no server is there.
  std::optional<Server> server();
  // The server (reply publisher id) is gone: every request pending there fails.
  void server_gone(std::uint32_t reply_publisher, const std::string& why);

  const std::string name;
  const std::shared_ptr<NodeState> node;
  const std::shared_ptr<CallbackGroup> group;
  const std::size_t bound;
  PublisherCore requests;
  std::uint32_t reply_subscriber = 0;
  mutable std::mutex mutex;
  std::uint64_t next_sequence = 1;
  std::map<std::uint64_t, Pending> pending;
  std::optional<Server> current;
  std::shared_ptr<ServerWatch> watch;
  // Servers known gone whose endpoints may linger a moment (reply publisher ids).
  std::set<std::uint32_t> gone;
};

void ServerWatch::execute() {
  // A pidfd stays readable: point the descriptor at a quiet eventfd so that
  // the executor does not run this again.
  if (const int quiet = ::eventfd(0, EFD_CLOEXEC); quiet >= 0) {
    ::dup2(quiet, pidfd_);
    ::close(quiet);
  }
  if (auto client = client_.lock()) client->server_gone(server_, "its process exited");
}

std::optional<Server> ClientCore::State::server() {
  {
    std::lock_guard lock(mutex);
    if (current) return current;
  }
  Kernel& kernel = Runtime::get().kernel();
  const auto find = [&]() -> std::optional<Server> {
    TopicInfo replies;
    TopicInfo asked;
    if (!kernel.topic_info(service_reply_topic(name), replies)) return std::nullopt;
    std::optional<Server> found;
    {
      std::lock_guard lock(mutex);
      for (const auto& publisher : replies.publishers) {
        if (gone.contains(publisher.id)) continue;
        if (!found || publisher.id < found->reply_publisher) {
          found = Server{publisher.id, publisher.pid, 0};
        }
      }
    }
    if (!found || !kernel.topic_info(service_request_topic(name), asked)) return std::nullopt;
    // A process's newest request subscriber: an older one may linger while
    // requests of a server it destroyed are still held.
    bool subscribed = false;
    for (const auto& subscriber : asked.subscribers) {
      if (subscriber.pid != found->pid || subscriber.id < found->request_subscriber) continue;
      found->request_subscriber = subscriber.id;
      subscribed = true;
    }
    if (!subscribed) return std::nullopt;
    return found;
  };
  std::optional<Server> found = find();
  if (!found) return std::nullopt;
  const int pidfd = open_pidfd(found->pid);
  if (pidfd < 0) return std::nullopt;  // the process is gone already
  // The pid may have been reused before the pidfd was opened: the server's
  // endpoints still being there says it was not.
  const std::optional<Server> again = find();
  if (!again || again->reply_publisher != found->reply_publisher) {
    ::close(pidfd);
    return std::nullopt;
  }
  auto watch =
      std::make_shared<ServerWatch>(group, pidfd, weak_from_this(), found->reply_publisher);
  std::shared_ptr<ServerWatch> replaced;
  {
    std::lock_guard lock(mutex);
    if (current) return current;  // another thread found it meanwhile
    current = found;
    replaced = std::exchange(this->watch, watch);
  }
  if (replaced) node->remove_waitable(replaced->key());
  register_waitable(*node, watch);
  return found;
}

void ClientCore::State::server_gone(std::uint32_t reply_publisher, const std::string& why) {
  std::vector<Completion> failed;
  std::shared_ptr<ServerWatch> stopped;
  {
    std::lock_guard lock(mutex);
    gone.insert(reply_publisher);
    if (current && current->reply_publisher == reply_publisher) {
      current.reset();
      stopped = std::exchange(watch, nullptr);
    }
    for (auto it = pending.begin(); it != pending.end();) {
      if (it->second.server != reply_publisher) {
        ++it;
        continue;
      }
      failed.push_back(std::move(it->second.completion));
      it = pending.erase(it);
    }
  }
  if (stopped) node->remove_waitable(stopped->key());
  const auto error = std::make_exception_ptr(ServiceUnavailable(
      "agnocast: service " + name + ": the server went away (" + why + ") before answering"));
  for (auto& completion : failed) completion(nullptr, nullptr, error);
}

ClientCore::ClientCore(std::shared_ptr<NodeState> node, std::string_view service, const QoS& qos,
                       const MessageType& request_type, const MessageType& response_type,
                       const SubscriptionOptions& options)
    : SubscriptionBase(node, checked_reply_topic(service), reply_queue_qos(qos), response_type,
                       options, TopicUse::service_carrier) {
  state_ = std::make_shared<State>(std::move(node), service, qos, request_type, group());
  state_->reply_subscriber = id();
}

ClientCore::~ClientCore() {
  std::shared_ptr<ServerWatch> watch;
  std::map<std::uint64_t, State::Pending> pending;
  {
    std::lock_guard lock(state_->mutex);
    watch = std::exchange(state_->watch, nullptr);
    pending.swap(state_->pending);  // their futures break: nothing will answer them here
  }
  if (watch) state_->node->remove_waitable(watch->key());
}

const std::string& ClientCore::service_name() const { return state_->name; }

std::size_t ClientCore::pending() const {
  std::lock_guard lock(state_->mutex);
  return state_->pending.size();
}

std::size_t ClientCore::prune_pending() {
  std::map<std::uint64_t, State::Pending> pruned;
  {
    std::lock_guard lock(state_->mutex);
    pruned.swap(state_->pending);
  }
  return pruned.size();
}

bool ClientCore::forget(const RequestId& id) {
  std::optional<State::Pending> forgotten;  // its completion dies outside the lock
  std::lock_guard lock(state_->mutex);
  if (id.client != state_->reply_subscriber) return false;
  const auto it = state_->pending.find(id.sequence);
  if (it == state_->pending.end()) return false;
  forgotten = std::move(it->second);
  state_->pending.erase(it);
  return true;
}

bool ClientCore::service_is_ready() const { return state_->server().has_value(); }

bool ClientCore::wait_for_service(std::chrono::nanoseconds timeout) const {
  // Nothing wakes a client when a server appears: poll, often enough for
  // start-up ordering and cheap next to a process start.
  constexpr auto interval = std::chrono::milliseconds{5};
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (service_is_ready()) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) return false;
    std::this_thread::sleep_for(std::min<std::chrono::nanoseconds>(interval, deadline - now));
  }
}

RequestId ClientCore::send(void* request, std::size_t bytes, Completion completion) {
  State& state = *state_;
  {
    std::lock_guard lock(state.mutex);
    if (state.pending.size() >= state.bound) {
      discard_message(request);
      throw TooManyRequests("agnocast: service " + state.name + ": " + std::to_string(state.bound) +
                            " requests are in flight already, the client's bound (its QoS "
                            "depth); wait for answers or prune_pending_requests()");
    }
  }
  const auto fail = [&](auto error) {
    completion(nullptr, nullptr, std::make_exception_ptr(std::move(error)));
  };
  const std::optional<Server> server = state.server();
  RequestId id{state.reply_subscriber, 0};
  if (!server) {
    discard_message(request);
    fail(ServiceUnavailable("agnocast: service " + state.name + " has no server"));
    return id;
  }
  {
    std::lock_guard lock(state.mutex);
    id.sequence = state.next_sequence++;
    if (state.gone.contains(server->reply_publisher)) {
      discard_message(request);
      fail(ServiceUnavailable("agnocast: service " + state.name + ": the server went away"));
      return id;
    }
    state.pending.emplace(id.sequence, State::Pending{server->reply_publisher, completion});
  }
  set_service_tag(request, ServiceTag{id.sequence, state.reply_subscriber, 0,
                                      static_cast<std::uint16_t>(ServiceStatus::request)});
  try {
    state.requests.publish(request, bytes, ServiceRoute{server->request_subscriber, true});
  } catch (const DeviceError& error) {
    // publish() freed the request. Whoever takes the pending entry completes it.
    std::optional<State::Pending> taken;
    {
      std::lock_guard lock(state.mutex);
      if (auto it = state.pending.find(id.sequence); it != state.pending.end()) {
        taken = std::move(it->second);
        state.pending.erase(it);
      }
    }
    switch (error.code()) {
      case ENXIO:  // the server's request subscriber is gone: so is the server
      case EPIPE:
        state.server_gone(server->reply_publisher, "its request subscriber is gone");
        if (taken)
          fail(ServiceUnavailable("agnocast: service " + state.name + ": the server went away"));
        break;
      case EAGAIN:
        if (taken) {
          fail(RequestRejected("agnocast: service " + state.name +
                               ": the server's request queue is full; the request was not sent"));
        }
        break;
      default:
        throw;
    }
  }
  return id;
}

void ClientCore::deliver(const void* message, EntryReference* reference, const MessageInfo& info) {
  const ServiceTag tag = read_service_tag(message);
  State& state = *state_;
  if (tag.status == static_cast<std::uint16_t>(ServiceStatus::server_gone)) {
    release(reference);
    state.server_gone(info.publisher_id, "it stopped");
    return;
  }
  std::optional<State::Pending> answered;
  {
    std::lock_guard lock(state.mutex);
    const auto it = state.pending.find(tag.sequence);
    // Only the server the request went to may answer it.
    if ((tag.status == static_cast<std::uint16_t>(ServiceStatus::response) ||
         tag.status == static_cast<std::uint16_t>(ServiceStatus::failed)) &&
        it != state.pending.end() && it->second.server == info.publisher_id) {
      answered = std::move(it->second);
      state.pending.erase(it);
    }
  }
  if (!answered) {
    release(reference);  // an answer to a pruned request
    return;
  }
  if (tag.status == static_cast<std::uint16_t>(ServiceStatus::failed)) {
    release(reference);
    answered->completion(nullptr, nullptr,
                         std::make_exception_ptr(ServiceUnavailable(
                             "agnocast: service " + state.name + ": the server could not answer")));
    return;
  }
  answered->completion(message, reference, nullptr);
}

}  // namespace agnocast::detail
