// A periodic timer as a descriptor (timerfd, CLOCK_MONOTONIC) for a daemon's
// event loop: poll fd(), call consume() when it is readable.
//
//   agnocast_service::PeriodicTimer status_timer(std::chrono::seconds(1));
#pragma once

#include <chrono>
#include <cstdint>

#include "agnocast_service/unique_fd.hpp"

namespace agnocast_service {

class PeriodicTimer {
 public:
  // Fires every period from now; never while period is zero. Throws
  // std::system_error.
  explicit PeriodicTimer(std::chrono::microseconds period);
  int fd() const { return fd_.get(); }
  // Restarts it to fire every period from now (zero: stops it).
  void arm(std::chrono::microseconds period);
  // The expirations since the last call, consumed (0 when none).
  std::uint64_t consume();

 private:
  UniqueFd fd_;
};

}  // namespace agnocast_service
