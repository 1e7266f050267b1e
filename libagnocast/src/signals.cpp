#include "agnocast/signals.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <mutex>

#include "signals_internal.hpp"

namespace agnocast {
namespace {

std::atomic<bool> signal_received{false};
int signal_eventfd = -1;
struct sigaction previous_sigint;
struct sigaction previous_sigterm;

void call_previous(const struct sigaction& previous, int signal, siginfo_t* info, void* context) {
  if (previous.sa_flags & SA_SIGINFO) {
    if (previous.sa_sigaction) previous.sa_sigaction(signal, info, context);
  } else if (previous.sa_handler != SIG_DFL && previous.sa_handler != SIG_IGN) {
    previous.sa_handler(signal);
  }
}

// Async-signal-safe: an atomic store and a write().
void on_signal(int signal, siginfo_t* info, void* context) {
  const int saved_errno = errno;
  signal_received.store(true);
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t written = ::write(signal_eventfd, &one, sizeof one);
  call_previous(signal == SIGINT ? previous_sigint : previous_sigterm, signal, info, context);
  errno = saved_errno;
}

}  // namespace

void install_signal_handlers() {
  static std::once_flag installed;
  std::call_once(installed, [] {
    signal_eventfd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    struct sigaction action {};
    action.sa_sigaction = &on_signal;
    action.sa_flags = SA_SIGINFO | SA_RESTART;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, &previous_sigint);
    ::sigaction(SIGTERM, &action, &previous_sigterm);
  });
}

bool ok() { return !signal_received.load(); }

namespace detail {

int shutdown_eventfd() {
  install_signal_handlers();
  return signal_eventfd;
}

}  // namespace detail
}  // namespace agnocast
