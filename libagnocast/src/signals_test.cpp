#include "agnocast/signals.hpp"

#include <gtest/gtest.h>
#include <poll.h>

#include <csignal>
#include <cstdlib>

#include "signals_internal.hpp"

namespace agnocast {
namespace {

int previous_calls = 0;

void raise_sigint_after_a_previous_handler() {
  std::signal(SIGINT, [](int) { ++previous_calls; });
  install_signal_handlers();
  if (!ok()) std::exit(1);
  std::raise(SIGINT);
  pollfd entry{detail::shutdown_eventfd(), POLLIN, 0};
  const bool woke = ::poll(&entry, 1, 0) == 1;
  std::exit(!ok() && woke && previous_calls == 1 ? 0 : 2);
}

void raise_sigterm() {
  install_signal_handlers();
  std::raise(SIGTERM);
  std::exit(ok() ? 1 : 0);
}

// Each case runs in a forked child: a delivered SIGINT is process-wide and final.
TEST(SignalsDeathTest, SigintStopsAndChainsThePreviousHandler) {
  EXPECT_EXIT(raise_sigint_after_a_previous_handler(), ::testing::ExitedWithCode(0), "");
}

TEST(SignalsDeathTest, SigtermDoesNotKillTheProcess) {
  EXPECT_EXIT(raise_sigterm(), ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace agnocast
