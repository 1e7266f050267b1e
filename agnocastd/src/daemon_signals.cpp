#include "daemon_signals.hpp"

#include <spdlog/spdlog.h>

#include <cstring>

#include "agnocast_service/signals.hpp"

namespace agnocastd {

bool stop_requested(std::chrono::milliseconds wait) {
  const int signal =
      agnocast_service::wait_for_signal(agnocast_service::signal_set({SIGTERM, SIGINT}), wait);
  if (signal == 0) return false;
  spdlog::info("received {} while starting, stopping", strsignal(signal));
  return true;
}

}  // namespace agnocastd
