// systemd's watchdog (WatchdogSec=), pinged only while the daemon is healthy:
// a daemon that is stuck, or whose health check fails, stops pinging and
// systemd restarts it. Put fd() in the event loop beside the daemon's work,
// so that a stuck loop does not ping either.
//
//   agnocast_service::Watchdog watchdog;            // poll watchdog.fd()
//   if (readable) watchdog.tick(my_health_check());
#pragma once

#include <chrono>
#include <optional>

#include "agnocast_service/timer.hpp"

namespace agnocast_service {

class Watchdog {
 public:
  // A timer of watchdog_ping_interval() (notify.hpp), or one that never
  // fires when systemd does not watch this process.
  Watchdog();
  // How often it pings; nullopt when systemd does not watch.
  std::optional<std::chrono::microseconds> interval() const { return interval_; }
  int fd() const { return timer_.fd(); }
  // When fd() is readable: consumes the tick and sends WATCHDOG=1 if
  // healthy; true when it did.
  bool tick(bool healthy);

 private:
  std::optional<std::chrono::microseconds> interval_;
  PeriodicTimer timer_;
};

}  // namespace agnocast_service
