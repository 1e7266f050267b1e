// sd_notify over the NOTIFY_SOCKET datagram protocol: a no-op outside systemd.
#pragma once

#include <chrono>
#include <optional>
#include <string_view>

namespace agnocastd {

// Sends state (e.g. "READY=1") to the service manager; false when not under
// systemd or the send failed.
bool notify(std::string_view state);

// Half of WatchdogSec when systemd watches this process, else nullopt.
std::optional<std::chrono::microseconds> watchdog_ping_interval();

}  // namespace agnocastd
