// How the library reports what it cannot throw: to the handler set with
// agnocast::set_log_handler, never to stdout or stderr.
#pragma once

#include <string_view>

#include "agnocast/log.hpp"

namespace agnocast::detail {

void log(LogLevel level, std::string_view message) noexcept;

}  // namespace agnocast::detail
