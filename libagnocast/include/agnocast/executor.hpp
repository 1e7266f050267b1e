#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>

#include "agnocast/node.hpp"

namespace agnocast {

// Waits (epoll) on the notification queues of the subscriptions of its nodes,
// their timers and added file descriptors, and runs their callbacks. spin()
// returns after cancel() or SIGINT/SIGTERM.
class Executor {
 public:
  virtual ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  // Subscriptions and timers the node creates later are picked up too.
  void add_node(Node& node);
  void remove_node(Node& node);

  // Runs on_ready whenever fd is readable (level-triggered: on_ready must
  // consume what made it so, e.g. read it, or it runs again). The descriptor
  // stays the caller's; remove it before closing it. group empty: a
  // MutuallyExclusive group of its own.
  void add_fd(int fd, std::function<void()> on_ready,
              std::shared_ptr<CallbackGroup> group = nullptr);
  void remove_fd(int fd);

  virtual void spin() = 0;
  // Runs the callbacks of everything that is ready now, without waiting.
  void spin_some();
  // Waits up to timeout for one ready subscription, timer or descriptor and
  // handles it; false if none was.
  bool spin_once(std::chrono::milliseconds timeout);
  // Makes spin() return; safe from any thread.
  void cancel();

 protected:
  // parallel: several threads spin at once, so each wake-up is handed to one
  // thread only (and re-armed after), which costs a system call per wake-up.
  explicit Executor(bool parallel);
  // One spinning thread's loop, shared by every thread of a spin().
  void spin_loop();
  // Clears an earlier cancel() so that a new spin() runs.
  void begin_spin();

 private:
  struct State;
  // Runs waitable within its callback group's rule: one at a time for a
  // MutuallyExclusive group (a thread finding the group busy leaves the work
  // to the thread running it), freely for a Reentrant one.
  static void run_in_group(detail::PendingWork work);

  std::unique_ptr<State> state_;
};

class SingleThreadedExecutor : public Executor {
 public:
  SingleThreadedExecutor() : Executor(/*parallel=*/false) {}
  void spin() override;
};

// Runs callbacks in parallel on several threads, as their callback groups
// allow (a node's default group is MutuallyExclusive); one subscription's or
// timer's callbacks never overlap.
class MultiThreadedExecutor : public Executor {
 public:
  explicit MultiThreadedExecutor(std::size_t threads = 0);  // 0: one per CPU
  void spin() override;

 private:
  std::size_t threads_;
};

}  // namespace agnocast
