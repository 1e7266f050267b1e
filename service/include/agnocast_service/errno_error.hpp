// std::system_error from errno, for a daemon's OS calls.
//
//   if (::sigprocmask(SIG_BLOCK, &set, nullptr) != 0) agnocast_service::throw_errno("sigprocmask");
#pragma once

#include <cerrno>
#include <string>
#include <system_error>

namespace agnocast_service {

[[noreturn]] inline void throw_errno(const std::string& what) {
  throw std::system_error(errno, std::generic_category(), what);
}

}  // namespace agnocast_service
