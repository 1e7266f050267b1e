// systemd's notification protocol (sd_notify), without libsystemd: one datagram
// to $NOTIFY_SOCKET. Does nothing when not started by systemd.
#pragma once

#include <chrono>
#include <optional>
#include <string_view>

namespace agnocast_bridge {

void notify_systemd(std::string_view state);
// Half of WatchdogSec when systemd watches this process, else nullopt.
std::optional<std::chrono::milliseconds> watchdog_interval();

}  // namespace agnocast_bridge
