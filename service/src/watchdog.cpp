#include "agnocast_service/watchdog.hpp"

#include "agnocast_service/notify.hpp"

namespace agnocast_service {

Watchdog::Watchdog()
    : interval_(watchdog_ping_interval()),
      timer_(interval_.value_or(std::chrono::microseconds{0})) {}

bool Watchdog::tick(bool healthy) {
  timer_.consume();
  return healthy && notify("WATCHDOG=1");
}

}  // namespace agnocast_service
