// A bounded wait for a descriptor, which the tests use instead of blocking.
#pragma once

#include <poll.h>

#include <chrono>

namespace agnocast_service {

// Whether `fd` becomes readable within `wait`.
inline bool readable(int fd, std::chrono::milliseconds wait) {
  pollfd entry{fd, POLLIN, 0};
  return ::poll(&entry, 1, static_cast<int>(wait.count())) == 1;
}

}  // namespace agnocast_service
