#include "agnocast/executor.hpp"

#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "agnocast/errors.hpp"
#include "agnocast/signals.hpp"
#include "node_state.hpp"
#include "signals_internal.hpp"

namespace agnocast {
namespace {

// epoll keys besides subscription keys (which count up from 1).
constexpr std::uint64_t shutdown_key = ~std::uint64_t{0};
constexpr std::uint64_t cancel_key = shutdown_key - 1;
constexpr std::uint64_t change_key = shutdown_key - 2;

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

}  // namespace

struct Executor::State {
  enum class Outcome { handled, idle, stop };

  explicit State(bool parallel)
      : subscription_events(parallel ? EPOLLIN | EPOLLONESHOT : EPOLLIN),
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
    ::close(epoll_fd);
    ::close(cancel_fd);
    ::close(change_fd);
  }

  // Arms subscriptions the nodes gained and forgets destroyed ones (their
  // closed queue descriptors have left the epoll set by themselves).
  void sync() {
    std::lock_guard lock(mutex);
    drain_eventfd(change_fd);
    std::erase_if(armed, [](const auto& entry) { return entry.second.expired(); });
    for (const auto& node : nodes) {
      for (const auto& weak : node->subscriptions_snapshot()) {
        const auto subscription = weak.lock();
        if (!subscription || armed.contains(subscription->key())) continue;
        watch(epoll_fd, subscription->queue_fd(), subscription->key(), subscription_events,
              EPOLL_CTL_ADD);
        armed.emplace(subscription->key(), weak);
      }
    }
  }

  Outcome handle(std::uint64_t key) {
    if (key == shutdown_key || key == cancel_key) return Outcome::stop;
    if (key == change_key) {
      sync();
      return Outcome::idle;
    }
    std::shared_ptr<detail::SubscriptionBase> subscription;
    {
      std::lock_guard lock(mutex);
      if (auto found = armed.find(key); found != armed.end()) subscription = found->second.lock();
    }
    if (!subscription) return Outcome::idle;
    // Re-arm even when a callback throws, or the subscription would go deaf.
    struct Rearm {
      int epoll_fd;
      std::uint32_t events;
      const detail::SubscriptionBase& subscription;
      ~Rearm() {
        if (!(events & EPOLLONESHOT)) return;
        epoll_event event{};
        event.events = events;
        event.data.u64 = subscription.key();
        ::epoll_ctl(epoll_fd, EPOLL_CTL_MOD, subscription.queue_fd(), &event);
      }
    } rearm{epoll_fd, subscription_events, *subscription};
    subscription->handle_wakeup();
    return Outcome::handled;
  }

  Outcome wait_and_handle(int timeout_ms) {
    epoll_event event{};
    const int ready = ::epoll_wait(epoll_fd, &event, 1, timeout_ms);
    if (ready < 0) {
      if (errno == EINTR) return Outcome::idle;
      throw Error(std::string("agnocast: epoll_wait: ") + std::strerror(errno));
    }
    if (ready == 0) return Outcome::idle;
    return handle(event.data.u64);
  }

  const std::uint32_t subscription_events;
  const int epoll_fd;
  const int cancel_fd;
  const int change_fd;
  std::mutex mutex;  // nodes and armed
  std::vector<std::shared_ptr<detail::NodeState>> nodes;
  std::map<std::uint64_t, std::weak_ptr<detail::SubscriptionBase>> armed;
};

Executor::Executor(bool parallel) : state_(std::make_unique<State>(parallel)) {}
Executor::~Executor() = default;

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
  for (const auto& weak : node.state()->subscriptions_snapshot()) {
    const auto subscription = weak.lock();
    if (!subscription || !state_->armed.erase(subscription->key())) continue;
    ::epoll_ctl(state_->epoll_fd, EPOLL_CTL_DEL, subscription->queue_fd(), nullptr);
  }
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
