// Signals read from a descriptor instead of caught by handlers: block them in
// the process first (before any thread starts, so that every thread inherits
// the mask and none runs the default action), then read them from a SignalFd
// in the event loop, or wait for them while the daemon starts.
//
//   const sigset_t stop = agnocast_service::signal_set({SIGTERM, SIGINT});
//   agnocast_service::block_signals(stop);          // first thing in main()
//   agnocast_service::SignalFd signals(stop);       // poll signals.fd() ...
//   while (const auto signal = signals.read()) ...  // ... when it is readable
#pragma once

#include <signal.h>

#include <chrono>
#include <initializer_list>
#include <optional>

#include "agnocast_service/unique_fd.hpp"

namespace agnocast_service {

sigset_t signal_set(std::initializer_list<int> signals);

// Adds signals to the calling thread's mask (the process's, before other
// threads exist) so that they queue until read. Throws std::system_error.
void block_signals(const sigset_t& signals);

// Waits up to `wait` for one of `signals` (blocked) and consumes it: its
// number, or 0 when none came. Other blocked signals stay pending. Throws
// std::system_error.
int wait_for_signal(const sigset_t& signals, std::chrono::milliseconds wait);

// A non-blocking signalfd for blocked signals.
class SignalFd {
 public:
  // Throws std::system_error.
  explicit SignalFd(const sigset_t& signals);
  int fd() const { return fd_.get(); }
  // The next pending signal, consumed; nullopt when none is.
  std::optional<int> read();

 private:
  UniqueFd fd_;
};

}  // namespace agnocast_service
