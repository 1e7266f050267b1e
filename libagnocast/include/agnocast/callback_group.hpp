#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>

namespace agnocast {

namespace detail {
class Waitable;

// Ready work a busy MutuallyExclusive group keeps for the thread running it,
// with the executor's epoll set to re-arm it in afterwards.
struct PendingWork {
  std::shared_ptr<Waitable> waitable;
  int epoll_fd = -1;
  std::uint32_t events = 0;
};
}  // namespace detail

enum class CallbackGroupType {
  // One callback of the group at a time, whatever the executor's threads.
  MutuallyExclusive,
  // The group's callbacks run in parallel on a MultiThreadedExecutor (each
  // subscription still delivers its own messages one at a time, in order).
  Reentrant,
};

// Which callbacks a MultiThreadedExecutor may run at the same time. Made by
// Node::create_callback_group(); a node's default group is MutuallyExclusive.
class CallbackGroup {
 public:
  explicit CallbackGroup(CallbackGroupType type) : type_(type) {}
  CallbackGroup(const CallbackGroup&) = delete;
  CallbackGroup& operator=(const CallbackGroup&) = delete;

  CallbackGroupType type() const { return type_; }

 private:
  friend class Executor;

  const CallbackGroupType type_;
  // Executor bookkeeping: a thread runs the group's callbacks while `running`;
  // others leave their ready callbacks in `pending` for it.
  std::mutex mutex_;
  bool running_ = false;
  std::deque<detail::PendingWork> pending_;
};

}  // namespace agnocast
