#include "agnocast/timer.hpp"

#include <sys/timerfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "agnocast/errors.hpp"
#include "tracing/trace.hpp"

namespace agnocast {
namespace {

int make_timerfd() {
  const int fd = ::timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK);
  if (fd < 0) throw Error(std::string("agnocast: timerfd_create: ") + std::strerror(errno));
  return fd;
}

timespec to_timespec(std::chrono::nanoseconds duration) {
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(duration);
  return timespec{static_cast<time_t>(seconds.count()),
                  static_cast<long>((duration - seconds).count())};
}

}  // namespace

Timer::Timer(std::chrono::nanoseconds period, std::function<void()> callback,
             std::shared_ptr<CallbackGroup> group)
    : Waitable(std::move(group)),
      period_(period),
      callback_(std::move(callback)),
      fd_(period > std::chrono::nanoseconds::zero()
              ? make_timerfd()
              : throw std::invalid_argument("agnocast: a timer's period must be positive")) {
  arm(true);
}

Timer::~Timer() {
  AGNOCAST_FORGET_INIT(this);
  ::close(fd_);
}

void Timer::arm(bool on) {
  itimerspec spec{};
  if (on) spec = itimerspec{to_timespec(period_), to_timespec(period_)};
  if (::timerfd_settime(fd_, 0, &spec, nullptr) != 0) {
    throw Error(std::string("agnocast: timerfd_settime: ") + std::strerror(errno));
  }
}

void Timer::cancel() {
  canceled_ = true;
  arm(false);
}

void Timer::reset() {
  canceled_ = false;
  arm(true);
}

void Timer::execute() {
  std::uint64_t expirations = 0;
  // Nothing to read: cancel() or reset() cleared the expiry after epoll saw it.
  if (::read(fd_, &expirations, sizeof expirations) != sizeof expirations) return;
  if (canceled_) return;
  const detail::TracedCallable traced(this);
  callback_();
}

}  // namespace agnocast
