#include "agnocast_service/signals.hpp"

#include <sys/signalfd.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>

#include "agnocast_service/errno_error.hpp"

namespace agnocast_service {

sigset_t signal_set(std::initializer_list<int> signals) {
  sigset_t set;
  sigemptyset(&set);
  for (const int signal : signals) sigaddset(&set, signal);
  return set;
}

void block_signals(const sigset_t& signals) {
  if (::pthread_sigmask(SIG_BLOCK, &signals, nullptr) != 0) throw_errno("pthread_sigmask");
}

int wait_for_signal(const sigset_t& signals, std::chrono::milliseconds wait) {
  const auto nanoseconds = std::chrono::nanoseconds(wait).count();
  const timespec timeout{static_cast<time_t>(nanoseconds / 1'000'000'000),
                         static_cast<long>(nanoseconds % 1'000'000'000)};
  int signal = -1;
  do {
    signal = ::sigtimedwait(&signals, nullptr, &timeout);
  } while (signal < 0 && errno == EINTR);
  if (signal < 0) {
    if (errno != EAGAIN) throw_errno("sigtimedwait");
    return 0;
  }
  return signal;
}

SignalFd::SignalFd(const sigset_t& signals)
    : fd_(::signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC)) {
  if (!fd_) throw_errno("signalfd");
}

std::optional<int> SignalFd::read() {
  signalfd_siginfo info{};
  if (::read(fd_.get(), &info, sizeof(info)) != sizeof(info)) return std::nullopt;
  return static_cast<int>(info.ssi_signo);
}

}  // namespace agnocast_service
