// The programs agnocastd runs (modprobe, modinfo). A child starts with an
// empty signal mask and default dispositions: it must not inherit the
// daemon's blocked stop signals, or SIGTERM could not stop it.
#pragma once

#include <string>
#include <vector>

namespace agnocastd {

struct ChildResult {
  bool exited_zero = false;
  std::string output;  // its stdout
};

// Runs argv (argv[0] looked up in PATH) to completion and captures stdout;
// its stderr is discarded (the caller says what failed).
// Throws std::system_error when it cannot start.
ChildResult run_child(const std::vector<std::string>& argv);

// Runs argv (argv[0] looked up in PATH) and waits for it, polling for stop
// signals: on SIGTERM or SIGINT the child gets SIGTERM (SIGKILL a second
// later), is reaped, and StopRequested is thrown. True when it exited 0.
bool run_child_until_stopped(const std::vector<std::string>& argv);

}  // namespace agnocastd
