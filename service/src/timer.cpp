#include "agnocast_service/timer.hpp"

#include <sys/timerfd.h>
#include <unistd.h>

#include "agnocast_service/errno_error.hpp"

namespace agnocast_service {

PeriodicTimer::PeriodicTimer(std::chrono::microseconds period)
    : fd_(::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC)) {
  if (!fd_) throw_errno("timerfd_create");
  if (period.count() > 0) arm(period);
}

void PeriodicTimer::arm(std::chrono::microseconds period) {
  itimerspec spec{};
  spec.it_interval.tv_sec = period.count() / 1'000'000;
  spec.it_interval.tv_nsec = (period.count() % 1'000'000) * 1000;
  spec.it_value = spec.it_interval;
  if (::timerfd_settime(fd_.get(), 0, &spec, nullptr) != 0) throw_errno("timerfd_settime");
}

std::uint64_t PeriodicTimer::consume() {
  std::uint64_t expirations = 0;
  if (::read(fd_.get(), &expirations, sizeof(expirations)) != sizeof(expirations)) return 0;
  return expirations;
}

}  // namespace agnocast_service
