// What an executor waits on: a descriptor that becomes readable, and the
// callbacks to run then. Subscriptions, timers and added descriptors are waitables.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>

#include "agnocast/callback_group.hpp"

namespace agnocast::detail {

class Waitable {
 public:
  virtual ~Waitable();
  Waitable(const Waitable&) = delete;
  Waitable& operator=(const Waitable&) = delete;

  virtual int wait_fd() const = 0;
  // Handles the descriptor's readiness; called by one thread at a time.
  virtual void execute() = 0;
  // Work the library does for itself (no callback runs): an executor's
  // spin_once() keeps waiting after it.
  virtual bool housekeeping() const { return false; }

  // Work due at a time rather than on readiness.  An executor that arms this
  // waitable calls watch_deadline(true); when that returns true it waits no
  // longer than deadline() (time_point::max(): none) and then calls expire(),
  // so the waitable needs no timer descriptor of its own.  watch_deadline(false)
  // when the executor lets it go.  expire() may come early or from any thread.
  using Clock = std::chrono::steady_clock;
  virtual bool watch_deadline(bool /*watched*/) { return false; }
  virtual Clock::time_point deadline() const { return Clock::time_point::max(); }
  virtual void expire() {}

  std::uint64_t key() const { return key_; }  // unique in the process, for executors
  const std::shared_ptr<CallbackGroup>& group() const { return group_; }

 protected:
  explicit Waitable(std::shared_ptr<CallbackGroup> group);

 private:
  const std::uint64_t key_;
  const std::shared_ptr<CallbackGroup> group_;
};

}  // namespace agnocast::detail
