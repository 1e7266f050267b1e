#pragma once

#include <chrono>
#include <cstddef>
#include <memory>

#include "agnocast/node.hpp"

namespace agnocast {

// Waits (epoll) on the notification queues of the subscriptions of its nodes
// and runs their callbacks. spin() returns after cancel() or SIGINT/SIGTERM.
class Executor {
 public:
  virtual ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  // Subscriptions the node creates later are picked up too.
  void add_node(Node& node);
  void remove_node(Node& node);

  virtual void spin() = 0;
  // Runs the callbacks of every subscription that is ready now, without waiting.
  void spin_some();
  // Waits up to timeout for one ready subscription and handles it; false if none was.
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
  std::unique_ptr<State> state_;
};

class SingleThreadedExecutor : public Executor {
 public:
  SingleThreadedExecutor() : Executor(/*parallel=*/false) {}
  void spin() override;
};

// Subscriptions run in parallel on several threads; one subscription's
// callbacks never overlap.
class MultiThreadedExecutor : public Executor {
 public:
  explicit MultiThreadedExecutor(std::size_t threads = 0);  // 0: one per CPU
  void spin() override;

 private:
  std::size_t threads_;
};

}  // namespace agnocast
