#include "daemon_signals.hpp"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstring>

#include "errno_error.hpp"

namespace agnocastd {

sigset_t daemon_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  return signals;
}

void block_daemon_signals() {
  const sigset_t signals = daemon_signals();
  if (::sigprocmask(SIG_BLOCK, &signals, nullptr) != 0) throw_errno("sigprocmask");
}

bool stop_requested(std::chrono::milliseconds wait) {
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  const auto nanoseconds = std::chrono::nanoseconds(wait).count();
  const timespec timeout{static_cast<time_t>(nanoseconds / 1'000'000'000),
                         static_cast<long>(nanoseconds % 1'000'000'000)};
  int signal = -1;
  do {
    signal = ::sigtimedwait(&stop_signals, nullptr, &timeout);
  } while (signal < 0 && errno == EINTR);
  if (signal < 0) {
    if (errno != EAGAIN) throw_errno("sigtimedwait");
    return false;
  }
  spdlog::info("received {} while starting, stopping", strsignal(signal));
  return true;
}

}  // namespace agnocastd
