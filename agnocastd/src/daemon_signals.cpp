#include "daemon_signals.hpp"

#include <spdlog/spdlog.h>

#include <cstring>

#include "agnocast_service/signals.hpp"

namespace agnocastd {

sigset_t daemon_signals() { return agnocast_service::signal_set({SIGTERM, SIGINT, SIGHUP}); }

void block_daemon_signals() { agnocast_service::block_signals(daemon_signals()); }

bool stop_requested(std::chrono::milliseconds wait) {
  const int signal =
      agnocast_service::wait_for_signal(agnocast_service::signal_set({SIGTERM, SIGINT}), wait);
  if (signal == 0) return false;
  spdlog::info("received {} while starting, stopping", strsignal(signal));
  return true;
}

}  // namespace agnocastd
