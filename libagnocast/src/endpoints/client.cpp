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
#include <memory>
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
                 TopicUse::service_carrier),
        slots(bound) {
    free_slots.reserve(bound);
    for (std::size_t slot = bound; slot-- > 0;)
      free_slots.push_back(static_cast<std::uint32_t>(slot));
  }

  // A request in flight. Its sequence number names its slot (sequence %
  // bound), so an answer finds it without a search or an allocation.
  struct Slot {
    std::uint64_t sequence = 0;  // 0: free
    std::uint32_t server = 0;    // the reply publisher id it was sent to
    std::unique_ptr<PendingCall> call;
  };

  // The server to send to, found in the kernel's tables when there is none
  // yet, watched from then on; nullopt when no server is there.
  std::optional<Server> server();
  // The server (reply publisher id) is gone: every request pending there fails.
  void server_gone(std::uint32_t reply_publisher, const std::string& why);
  // Under mutex: a slot for a request to server, its sequence number set.
  std::uint64_t occupy(std::uint32_t server, std::unique_ptr<PendingCall>& call);
  // Under mutex: the call of the request sequence names, its slot freed;
  // null when that request is not pending.
  std::unique_ptr<PendingCall> vacate(std::uint64_t sequence, std::optional<std::uint32_t> server);
  // Under mutex: every pending call, or those sent to server, their slots freed.
  std::vector<std::unique_ptr<PendingCall>> vacate_all(std::optional<std::uint32_t> server);

  const std::string name;
  const std::shared_ptr<NodeState> node;
  const std::shared_ptr<CallbackGroup> group;
  const std::size_t bound;
  PublisherCore requests;
  std::uint32_t reply_subscriber = 0;
  mutable std::mutex mutex;
  std::vector<Slot> slots;
  std::vector<std::uint32_t> free_slots;
  std::uint64_t issued = 0;  // requests given a slot so far
  std::optional<Server> current;
  std::shared_ptr<ServerWatch> watch;
  // Servers known gone whose endpoints may linger a moment (reply publisher
  // ids); forgotten once their endpoints are seen gone.
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
      // A server whose endpoints are gone too need not be remembered.
      std::erase_if(gone, [&](std::uint32_t id) {
        return std::none_of(replies.publishers.begin(), replies.publishers.end(),
                            [id](const auto& publisher) { return publisher.id == id; });
      });
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

std::uint64_t ClientCore::State::occupy(std::uint32_t to, std::unique_ptr<PendingCall>& call) {
  const std::uint32_t slot = free_slots.back();
  free_slots.pop_back();
  // Never 0 (issued counts from 1), and slot again modulo bound.
  const std::uint64_t sequence = ++issued * bound + slot;
  slots[slot] = Slot{sequence, to, std::move(call)};
  return sequence;
}

std::unique_ptr<PendingCall> ClientCore::State::vacate(std::uint64_t sequence,
                                                       std::optional<std::uint32_t> from) {
  Slot& slot = slots[sequence % bound];
  if (sequence == 0 || slot.sequence != sequence || (from && slot.server != *from)) return nullptr;
  slot.sequence = 0;
  free_slots.push_back(static_cast<std::uint32_t>(sequence % bound));
  return std::move(slot.call);
}

std::vector<std::unique_ptr<PendingCall>> ClientCore::State::vacate_all(
    std::optional<std::uint32_t> to) {
  std::vector<std::unique_ptr<PendingCall>> calls;
  for (Slot& slot : slots) {
    if (slot.sequence != 0 && (!to || slot.server == *to)) {
      calls.push_back(vacate(slot.sequence, std::nullopt));
    }
  }
  return calls;
}

void ClientCore::State::server_gone(std::uint32_t reply_publisher, const std::string& why) {
  std::vector<std::unique_ptr<PendingCall>> failed;
  std::shared_ptr<ServerWatch> stopped;
  {
    std::lock_guard lock(mutex);
    gone.insert(reply_publisher);
    if (current && current->reply_publisher == reply_publisher) {
      current.reset();
      stopped = std::exchange(watch, nullptr);
    }
    failed = vacate_all(reply_publisher);
  }
  if (stopped) node->remove_waitable(stopped->key());
  const auto error = std::make_exception_ptr(ServiceUnavailable(
      "agnocast: service " + name + ": the server went away (" + why + ") before answering"));
  for (auto& call : failed) call->complete(nullptr, nullptr, error);
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
  std::vector<std::unique_ptr<PendingCall>> abandoned;  // their futures break
  {
    std::lock_guard lock(state_->mutex);
    watch = std::exchange(state_->watch, nullptr);
    abandoned = state_->vacate_all(std::nullopt);
  }
  if (watch) state_->node->remove_waitable(watch->key());
}

const std::string& ClientCore::service_name() const { return state_->name; }

std::size_t ClientCore::pending() const {
  std::lock_guard lock(state_->mutex);
  return state_->bound - state_->free_slots.size();
}

std::size_t ClientCore::prune_pending() {
  std::vector<std::unique_ptr<PendingCall>> pruned;  // destroyed outside the lock
  {
    std::lock_guard lock(state_->mutex);
    pruned = state_->vacate_all(std::nullopt);
  }
  return pruned.size();
}

bool ClientCore::forget(const RequestId& id) {
  std::unique_ptr<PendingCall> forgotten;  // destroyed outside the lock
  {
    std::lock_guard lock(state_->mutex);
    if (id.client != state_->reply_subscriber) return false;
    forgotten = state_->vacate(id.sequence, std::nullopt);
  }
  return forgotten != nullptr;
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

namespace {

class FunctionCall final : public PendingCall {
 public:
  explicit FunctionCall(ClientCore::Completion completion) : completion_(std::move(completion)) {}
  void complete(const void* response, EntryReference* reference,
                std::exception_ptr error) override {
    completion_(response, reference, std::move(error));
  }

 private:
  ClientCore::Completion completion_;
};

}  // namespace

RequestId ClientCore::send(void* request, std::size_t bytes, Completion completion) {
  std::unique_ptr<PendingCall> call;
  try {
    call = std::make_unique<FunctionCall>(std::move(completion));
  } catch (...) {
    discard_message(request);
    throw;
  }
  return send(request, bytes, std::move(call));
}

RequestId ClientCore::send(void* request, std::size_t bytes, std::unique_ptr<PendingCall> call) {
  State& state = *state_;
  const auto refuse_over_bound = [&] {
    discard_message(request);
    throw TooManyRequests("agnocast: service " + state.name + ": " + std::to_string(state.bound) +
                          " requests are in flight already, the client's bound (its QoS "
                          "depth); wait for answers or prune_pending_requests()");
  };
  const auto fail = [&](auto error) {
    discard_message(request);
    call->complete(nullptr, nullptr, std::make_exception_ptr(std::move(error)));
  };
  RequestId id{state.reply_subscriber, 0};
  std::optional<Server> server;
  {
    // The common case, one lock: a server known and watched (never one
    // known gone: server_gone() forgets it under this lock).
    std::lock_guard lock(state.mutex);
    if (state.free_slots.empty()) refuse_over_bound();
    if (state.current) {
      server = state.current;
      id.sequence = state.occupy(server->reply_publisher, call);
    }
  }
  if (!server) {
    server = state.server();
    if (!server) {
      fail(ServiceUnavailable("agnocast: service " + state.name + " has no server"));
      return id;
    }
    bool gone = false;
    {
      std::lock_guard lock(state.mutex);
      gone = state.gone.contains(server->reply_publisher);
      if (!gone && state.free_slots.empty()) refuse_over_bound();  // another thread took it
      if (!gone) id.sequence = state.occupy(server->reply_publisher, call);
    }
    if (gone) {
      fail(ServiceUnavailable("agnocast: service " + state.name + ": the server went away"));
      return id;
    }
  }
  set_service_tag(request, ServiceTag{id.sequence, state.reply_subscriber, 0,
                                      static_cast<std::uint16_t>(ServiceStatus::request)});
  try {
    state.requests.publish(request, bytes, ServiceRoute{server->request_subscriber, true});
  } catch (const DeviceError& error) {
    // publish() freed the request. Whoever takes the pending call completes it.
    std::unique_ptr<PendingCall> taken;
    {
      std::lock_guard lock(state.mutex);
      taken = state.vacate(id.sequence, std::nullopt);
    }
    const auto fail_taken = [&](auto failure) {
      if (taken) taken->complete(nullptr, nullptr, std::make_exception_ptr(std::move(failure)));
    };
    switch (error.code()) {
      case ENXIO:  // the server's request subscriber is gone: so is the server
      case EPIPE:
        state.server_gone(server->reply_publisher, "its request subscriber is gone");
        fail_taken(
            ServiceUnavailable("agnocast: service " + state.name + ": the server went away"));
        break;
      case EAGAIN:
        fail_taken(
            RequestRejected("agnocast: service " + state.name +
                            ": the server's request queue is full; the request was not sent"));
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
  std::unique_ptr<PendingCall> answered;
  if (tag.status == static_cast<std::uint16_t>(ServiceStatus::response) ||
      tag.status == static_cast<std::uint16_t>(ServiceStatus::failed)) {
    // Only the server the request went to may answer it.
    std::lock_guard lock(state.mutex);
    answered = state.vacate(tag.sequence, info.publisher_id);
  }
  if (!answered) {
    release(reference);  // an answer to a pruned request
    return;
  }
  if (tag.status == static_cast<std::uint16_t>(ServiceStatus::failed)) {
    release(reference);
    answered->complete(nullptr, nullptr,
                       std::make_exception_ptr(ServiceUnavailable(
                           "agnocast: service " + state.name + ": the server could not answer")));
    return;
  }
  answered->complete(message, reference, nullptr);
}

}  // namespace agnocast::detail
