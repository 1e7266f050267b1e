// systemd's notification protocol (sd_notify) without libsystemd: one
// datagram to $NOTIFY_SOCKET. Outside systemd every call is a no-op.
//
//   agnocast_service::notify("READY=1");         // Type=notify: started
//   agnocast_service::notify("STATUS=relaying 3 topics");
//   agnocast_service::notify("STOPPING=1");
//   if (auto every = agnocast_service::watchdog_ping_interval()) ...  // WatchdogSec
#pragma once

#include <chrono>
#include <optional>
#include <string_view>

namespace agnocast_service {

// Sends state (e.g. "READY=1", "WATCHDOG=1") to the service manager; false
// when not under systemd or the send failed.
bool notify(std::string_view state);

// Half of WatchdogSec when systemd watches this process (WATCHDOG_USEC, and
// WATCHDOG_PID when set is ours), else nullopt: how often to send WATCHDOG=1.
std::optional<std::chrono::microseconds> watchdog_ping_interval();

}  // namespace agnocast_service
