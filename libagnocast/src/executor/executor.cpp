#include "agnocast/executor.hpp"

#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/errors.hpp"
#include "agnocast/signals.hpp"
#include "endpoints/node_state.hpp"
#include "endpoints/notification_queue.hpp"
#include "kernel/runtime.hpp"
#include "signals_internal.hpp"
#include "tracing/trace.hpp"

namespace agnocast {
namespace {

// epoll keys besides waitable keys (which count up from 1).
constexpr std::uint64_t shutdown_key = ~std::uint64_t{0};
constexpr std::uint64_t cancel_key = shutdown_key - 1;
constexpr std::uint64_t change_key = shutdown_key - 2;
constexpr std::uint64_t wake_key = shutdown_key - 3;

int make_eventfd() {
  const int fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (fd < 0) throw Error(std::string("agnocast: eventfd: ") + std::strerror(errno));
  return fd;
}

void drain_eventfd(int fd) {
  std::uint64_t value;
  [[maybe_unused]] const ssize_t got = ::read(fd, &value, sizeof value);
}

void watch(int epoll_fd, int fd, std::uint64_t key, std::uint32_t events, int operation) {
  epoll_event event{};
  event.events = events;
  event.data.u64 = key;
  if (::epoll_ctl(epoll_fd, operation, fd, &event) != 0) {
    throw Error(std::string("agnocast: epoll_ctl: ") + std::strerror(errno));
  }
}

// A descriptor added with add_fd(): the executor holds it, not a node.
class FdWaitable : public detail::Waitable {
 public:
  FdWaitable(int fd, std::function<void()> on_ready, std::shared_ptr<CallbackGroup> group)
      : Waitable(std::move(group)), fd_(fd), on_ready_(std::move(on_ready)) {}
  int wait_fd() const override { return fd_; }
  void execute() override { on_ready_(); }

 private:
  const int fd_;
  const std::function<void()> on_ready_;
};

}  // namespace

struct Executor::State {
  enum class Outcome { handled, idle, stop };

  explicit State(bool parallel)
      : waitable_events(parallel ? EPOLLIN | EPOLLONESHOT : EPOLLIN),
        epoll_fd(::epoll_create1(EPOLL_CLOEXEC)),
        cancel_fd(make_eventfd()),
        change_fd(make_eventfd()) {
    if (epoll_fd < 0) throw Error(std::string("agnocast: epoll_create1: ") + std::strerror(errno));
    watch(epoll_fd, detail::shutdown_eventfd(), shutdown_key, EPOLLIN, EPOLL_CTL_ADD);
    watch(epoll_fd, cancel_fd, cancel_key, EPOLLIN, EPOLL_CTL_ADD);
    watch(epoll_fd, change_fd, change_key, EPOLLIN, EPOLL_CTL_ADD);
  }

  ~State() {
    for (const auto& node : nodes) node->remove_watcher(change_fd);
    for (const auto& weak : timed) {
      if (const auto waitable = weak.lock()) waitable->watch_deadline(false);
    }
    ::close(epoll_fd);
    ::close(cancel_fd);
    ::close(change_fd);
  }

  // Arms waitables the nodes gained and forgets destroyed ones (their
  // closed descriptors have left the epoll set by themselves).
  void sync() {
    std::lock_guard lock(mutex);
    drain_eventfd(change_fd);
    // The kernel's word that a notification may have been lost, once the
    // process has a runtime (its nodes make it).
    if (watched_wake_fd < 0) {
      const detail::Runtime* runtime = detail::Runtime::current();
      if (const int fd = runtime ? runtime->wake_fd() : -1; fd >= 0) {
        watch(epoll_fd, fd, wake_key, EPOLLIN, EPOLL_CTL_ADD);
        watched_wake_fd = fd;
      }
    }
    std::erase_if(armed, [](const auto& entry) { return entry.second.expired(); });
    std::erase_if(timed, [](const auto& weak) { return weak.expired(); });
    for (const auto& node : nodes) {
      for (const auto& weak : node->waitables_snapshot()) {
        const auto waitable = weak.lock();
        if (!waitable || armed.contains(waitable->key())) continue;
        watch(epoll_fd, waitable->wait_fd(), waitable->key(), waitable_events, EPOLL_CTL_ADD);
        armed.emplace(waitable->key(), weak);
        if (waitable->watch_deadline(true)) timed.push_back(weak);
      }
    }
  }

  // The waitable no longer watched, with mutex held.
  void unwatch(const std::shared_ptr<detail::Waitable>& waitable) {
    const auto found = std::find_if(timed.begin(), timed.end(), [&](const auto& weak) {
      return !weak.owner_before(waitable) && !waitable.owner_before(weak);
    });
    if (found == timed.end()) return;
    timed.erase(found);
    waitable->watch_deadline(false);
  }

  // The earliest deadline of the watched waitables (max(): none).
  detail::Waitable::Clock::time_point earliest_deadline() {
    auto earliest = detail::Waitable::Clock::time_point::max();
    std::lock_guard lock(mutex);
    for (const auto& weak : timed) {
      if (const auto waitable = weak.lock()) earliest = std::min(earliest, waitable->deadline());
    }
    return earliest;
  }

  // Runs the work of every watched waitable whose deadline has passed.
  void expire_due() {
    const auto now = detail::Waitable::Clock::now();
    std::lock_guard lock(mutex);
    for (const auto& weak : timed) {
      const auto waitable = weak.lock();
      if (waitable && waitable->deadline() <= now) waitable->expire();
    }
  }

  std::shared_ptr<detail::Waitable> find(std::uint64_t key) {
    std::lock_guard lock(mutex);
    if (auto found = armed.find(key); found != armed.end()) return found->second.lock();
    return nullptr;
  }

  Outcome handle(std::uint64_t key) {
    if (key == shutdown_key || key == cancel_key) return Outcome::stop;
    if (key == change_key) {
      sync();
      return Outcome::idle;
    }
    if (key == wake_key) {
      // Another executor of this process may have taken it first: it wakes
      // every queue of the process, ours too.
      std::uint64_t signals = 0;
      if (::read(watched_wake_fd, &signals, sizeof signals) == sizeof signals) {
        detail::OwnedQueue::wake_all();
      }
      return Outcome::idle;
    }
    std::shared_ptr<detail::Waitable> waitable = find(key);
    if (!waitable) return Outcome::idle;
    const bool housekeeping = waitable->housekeeping();
    run_in_group(detail::PendingWork{std::move(waitable), epoll_fd, waitable_events});
    return housekeeping ? Outcome::idle : Outcome::handled;
  }

  // Waits at most timeout_ms (-1: no limit) and at most until the earliest
  // deadline, then handles what is ready and, when the wait reached a
  // deadline, the deadlines due: no timer descriptor, no extra system call.
  Outcome wait_and_handle(int timeout_ms) {
    bool deadline_bound = false;
    if (const auto earliest = earliest_deadline();
        earliest != detail::Waitable::Clock::time_point::max()) {
      // Rounded up: the wait must not end before the deadline.
      const auto left =
          std::chrono::ceil<std::chrono::milliseconds>(earliest - detail::Waitable::Clock::now());
      const int left_ms = static_cast<int>(std::clamp<std::int64_t>(left.count(), 0, 1 << 30));
      if (timeout_ms < 0 || left_ms <= timeout_ms) {
        timeout_ms = left_ms;
        deadline_bound = true;
      }
    }
    epoll_event event{};
    AGNOCAST_REPLAY_INIT();  // for a session that enabled the events since
    AGNOCAST_TRACE(agnocast_executor_wait, this, static_cast<std::int32_t>(timeout_ms));
    const int ready = ::epoll_wait(epoll_fd, &event, 1, timeout_ms);
    AGNOCAST_TRACE(agnocast_executor_wake, this, static_cast<std::int32_t>(ready));
    if (ready < 0) {
      if (errno == EINTR) return Outcome::idle;
      throw Error(std::string("agnocast: epoll_wait: ") + std::strerror(errno));
    }
    const Outcome outcome = ready == 0 ? Outcome::idle : handle(event.data.u64);
    // An event before the deadline (timeout > 0) leaves the deadline for a
    // later wait; one that came with a deadline already due does not delay it.
    if (deadline_bound && (ready == 0 || timeout_ms == 0) && outcome != Outcome::stop) {
      expire_due();
    }
    return outcome;
  }

  const std::uint32_t waitable_events;
  const int epoll_fd;
  const int cancel_fd;
  const int change_fd;
  std::atomic<int> watched_wake_fd{-1};  // the runtime's, not ours to close
  std::mutex mutex;                      // nodes, armed, fds and watched_wake_fd
  std::vector<std::shared_ptr<detail::NodeState>> nodes;
  std::map<std::uint64_t, std::weak_ptr<detail::Waitable>> armed;
  std::map<int, std::shared_ptr<FdWaitable>> fds;  // what add_fd() added, by descriptor
  // Armed waitables whose deadlines this executor watches (Waitable::deadline).
  std::vector<std::weak_ptr<detail::Waitable>> timed;
};

namespace {

// One-shot descriptors wait again only once re-armed, which happens after
// each handling even when a callback threw, or the waitable would go deaf.
void rearm(const detail::PendingWork& work) {
  if (!(work.events & EPOLLONESHOT)) return;
  epoll_event event{};
  event.events = work.events;
  event.data.u64 = work.waitable->key();
  ::epoll_ctl(work.epoll_fd, EPOLL_CTL_MOD, work.waitable->wait_fd(), &event);
}

void execute_and_rearm(const detail::PendingWork& work) {
  struct Rearm {
    const detail::PendingWork& work;
    ~Rearm() { rearm(work); }
  } rearm_on_exit{work};
  work.waitable->execute();
}

}  // namespace

void Executor::run_in_group(detail::PendingWork work) {
  CallbackGroup& group = *work.waitable->group();
  if (group.type() == CallbackGroupType::Reentrant) {
    execute_and_rearm(work);
    return;
  }
  {
    std::lock_guard lock(group.mutex_);
    if (group.running_) {
      // Still disarmed (one-shot): the running thread executes and re-arms it.
      group.pending_.push_back(std::move(work));
      return;
    }
    group.running_ = true;
  }
  for (;;) {
    try {
      execute_and_rearm(work);
    } catch (...) {
      // Hand the group back; what waited is re-armed and fires again, as its
      // descriptor is still readable.
      std::deque<detail::PendingWork> left;
      {
        std::lock_guard lock(group.mutex_);
        group.running_ = false;
        left.swap(group.pending_);
      }
      for (const auto& pending : left) rearm(pending);
      throw;
    }
    std::lock_guard lock(group.mutex_);
    if (group.pending_.empty()) {
      group.running_ = false;
      return;
    }
    work = std::move(group.pending_.front());
    group.pending_.pop_front();
  }
}

// The executor's events name it by its state, which its waits know.
Executor::Executor(bool parallel) : state_(std::make_unique<State>(parallel)) {
  AGNOCAST_TRACE_INIT(state_.get(),
                      [executor = state_.get(),
                       kind = parallel ? "multi_threaded_executor" : "single_threaded_executor"] {
                        AGNOCAST_TRACE(agnocast_construct_executor, executor, kind);
                      });
}
Executor::~Executor() { AGNOCAST_FORGET_INIT(state_.get()); }

void Executor::add_node(Node& node) {
  {
    std::lock_guard lock(state_->mutex);
    if (std::find(state_->nodes.begin(), state_->nodes.end(), node.state()) !=
        state_->nodes.end()) {
      return;
    }
    state_->nodes.push_back(node.state());
    node.state()->add_watcher(state_->change_fd);
  }
  state_->sync();
}

void Executor::remove_node(Node& node) {
  std::lock_guard lock(state_->mutex);
  std::erase(state_->nodes, node.state());
  node.state()->remove_watcher(state_->change_fd);
  for (const auto& weak : node.state()->waitables_snapshot()) {
    const auto waitable = weak.lock();
    if (!waitable || !state_->armed.erase(waitable->key())) continue;
    ::epoll_ctl(state_->epoll_fd, EPOLL_CTL_DEL, waitable->wait_fd(), nullptr);
    state_->unwatch(waitable);
  }
}

void Executor::add_fd(int fd, std::function<void()> on_ready,
                      std::shared_ptr<CallbackGroup> group) {
  if (!group) group = std::make_shared<CallbackGroup>(CallbackGroupType::MutuallyExclusive);
  auto waitable = std::make_shared<FdWaitable>(fd, std::move(on_ready), std::move(group));
  std::lock_guard lock(state_->mutex);
  if (state_->fds.contains(fd)) {
    throw std::invalid_argument("agnocast: descriptor " + std::to_string(fd) +
                                " is already added to this executor");
  }
  watch(state_->epoll_fd, fd, waitable->key(), state_->waitable_events, EPOLL_CTL_ADD);
  state_->armed.emplace(waitable->key(), waitable);
  state_->fds.emplace(fd, std::move(waitable));
}

void Executor::remove_fd(int fd) {
  std::lock_guard lock(state_->mutex);
  const auto found = state_->fds.find(fd);
  if (found == state_->fds.end()) return;
  ::epoll_ctl(state_->epoll_fd, EPOLL_CTL_DEL, fd, nullptr);
  state_->armed.erase(found->second->key());
  state_->fds.erase(found);
}

void Executor::begin_spin() { drain_eventfd(state_->cancel_fd); }

void Executor::spin_loop() {
  while (ok() && state_->wait_and_handle(-1) != State::Outcome::stop) {
  }
}

void Executor::spin_some() {
  state_->sync();
  epoll_event events[64];
  const int ready = ::epoll_wait(state_->epoll_fd, events, 64, 0);
  for (int i = 0; i < ready; ++i) {
    if (state_->handle(events[i].data.u64) == State::Outcome::stop) return;
  }
  if (state_->earliest_deadline() != detail::Waitable::Clock::time_point::max()) {
    state_->expire_due();
  }
}

bool Executor::spin_once(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    // Rounded up: epoll_wait must not return before the deadline.
    const auto left =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    const auto outcome =
        state_->wait_and_handle(static_cast<int>(std::max<std::int64_t>(left.count(), 0)));
    if (outcome == State::Outcome::handled) return true;
    if (outcome == State::Outcome::stop || left.count() <= 0) return false;
  }
}

void Executor::cancel() {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t written = ::write(state_->cancel_fd, &one, sizeof one);
}

void SingleThreadedExecutor::spin() {
  begin_spin();
  spin_loop();
}

MultiThreadedExecutor::MultiThreadedExecutor(std::size_t threads)
    : Executor(/*parallel=*/true),
      threads_(threads ? threads : std::max(2U, std::thread::hardware_concurrency())) {}

void MultiThreadedExecutor::spin() {
  begin_spin();
  std::mutex failure_mutex;
  std::exception_ptr failure;
  auto run = [&] {
    try {
      spin_loop();
    } catch (...) {
      std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      cancel();  // the others stop too
    }
  };
  std::vector<std::thread> helpers;
  for (std::size_t i = 1; i < threads_; ++i) helpers.emplace_back(run);
  run();
  for (auto& helper : helpers) helper.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace agnocast
