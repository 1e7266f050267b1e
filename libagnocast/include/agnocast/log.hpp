#pragma once

#include <functional>
#include <string_view>

namespace agnocast {

enum class LogLevel { debug, info, warning, error };

using LogHandler = std::function<void(LogLevel level, std::string_view message)>;

// The library never writes to stdout or stderr: what it would warn about
// (failures it cannot throw, e.g. in destructors, or a subscriber's queue a
// publisher cannot notify) goes to this handler. Default: none, nothing is
// reported. May be called from any thread, including executor threads;
// replaceable at any time.
void set_log_handler(LogHandler handler);

}  // namespace agnocast
