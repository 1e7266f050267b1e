// A stop while agnocastd starts: the service loop blocks its signals
// (SIGTERM, SIGINT, SIGHUP) from the start so that they queue; they are polled
// here while the daemon starts so that a stop is honoured in every phase, and
// read by the serve loop after.
#pragma once

#include <signal.h>

#include <chrono>
#include <stdexcept>

namespace agnocastd {

// A stop signal came while the daemon was starting.
class StopRequested : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Waits up to `wait` for SIGTERM or SIGINT and consumes it; SIGHUP stays
// pending for the serve loop. True when one came.
bool stop_requested(std::chrono::milliseconds wait);

}  // namespace agnocastd
