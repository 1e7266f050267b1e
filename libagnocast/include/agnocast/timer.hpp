#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>

#include "agnocast/detail/waitable.hpp"

namespace agnocast {

// Runs its callback every period (steady clock) from an executor spinning its
// node. Made by Node::create_wall_timer(). Missed periods are not made up: a
// callback that overran runs once, then the timer keeps its phase.
class Timer : public detail::Waitable {
 public:
  Timer(std::chrono::nanoseconds period, std::function<void()> callback,
        std::shared_ptr<CallbackGroup> group);
  ~Timer() override;

  // Stops the timer; a callback already running finishes.
  void cancel();
  bool is_canceled() const { return canceled_; }
  // Restarts a full period from now (and un-cancels).
  void reset();
  std::chrono::nanoseconds period() const { return period_; }

  int wait_fd() const override { return fd_; }
  void execute() override;

 private:
  void arm(bool on);

  const std::chrono::nanoseconds period_;
  const std::function<void()> callback_;
  const int fd_;
  std::atomic<bool> canceled_{false};
};

}  // namespace agnocast
