// std::system_error from errno, for the daemon's OS calls.
#pragma once

#include <cerrno>
#include <string>
#include <system_error>

namespace agnocastd {

[[noreturn]] inline void throw_errno(const std::string& what) {
  throw std::system_error(errno, std::generic_category(), what);
}

}  // namespace agnocastd
