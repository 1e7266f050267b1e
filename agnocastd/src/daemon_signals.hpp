// The signals agnocastd serves (SIGTERM, SIGINT, SIGHUP): blocked from the
// start so that they queue, read by the serve loop's signalfd, and polled
// while the daemon starts so that a stop is honoured in every phase.
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

// SIGTERM, SIGINT and SIGHUP.
sigset_t daemon_signals();

// Blocks daemon_signals() so that they wait for serve() or stop_requested().
void block_daemon_signals();

// Waits up to `wait` for SIGTERM or SIGINT and consumes it; SIGHUP stays
// pending for the serve loop. True when one came.
bool stop_requested(std::chrono::milliseconds wait);

}  // namespace agnocastd
