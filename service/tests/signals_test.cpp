#include "agnocast_service/signals.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>

#include "agnocast_service/timer.hpp"
#include "agnocast_service/watchdog.hpp"
#include "fake_notify_socket.hpp"
#include "readable.hpp"

namespace agnocast_service {
namespace {

using namespace std::chrono_literals;

TEST(Signals, BlockedSignalsAreReadFromTheDescriptor) {
  const sigset_t usr = signal_set({SIGUSR1, SIGUSR2});
  block_signals(usr);
  SignalFd signals(usr);
  EXPECT_FALSE(signals.read());
  ::raise(SIGUSR2);
  ASSERT_TRUE(readable(signals.fd(), 1000ms));
  EXPECT_EQ(signals.read(), SIGUSR2);
  EXPECT_FALSE(signals.read());
}

TEST(Signals, WaitForSignalConsumesOneOrTimesOut) {
  const sigset_t usr1 = signal_set({SIGUSR1});
  block_signals(usr1);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(wait_for_signal(usr1, 50ms), 0);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 50ms);
  ::raise(SIGUSR1);
  EXPECT_EQ(wait_for_signal(usr1, 1000ms), SIGUSR1);
  EXPECT_EQ(wait_for_signal(usr1, 0ms), 0);  // consumed
}

TEST(PeriodicTimer, FiresEveryPeriodAndNeverAtZero) {
  PeriodicTimer timer(2ms);
  ASSERT_TRUE(readable(timer.fd(), 1000ms));
  EXPECT_GE(timer.consume(), 1u);
  timer.arm(0us);
  timer.consume();
  EXPECT_FALSE(readable(timer.fd(), 30ms));
  EXPECT_EQ(timer.consume(), 0u);
  PeriodicTimer never(0us);
  EXPECT_FALSE(readable(never.fd(), 30ms));
}

TEST(Watchdog, PingsOnlyWhenHealthy) {
  FakeNotifySocket systemd("agnocast-service-watchdog");
  ::unsetenv("WATCHDOG_PID");
  ::setenv("WATCHDOG_USEC", "20000", 1);  // a ping every 10 ms
  Watchdog watchdog;
  ::unsetenv("WATCHDOG_USEC");
  EXPECT_EQ(watchdog.interval(), 10ms);
  ASSERT_TRUE(readable(watchdog.fd(), 1000ms));
  EXPECT_FALSE(watchdog.tick(/*healthy=*/false));
  EXPECT_EQ(systemd.received(), "");
  ASSERT_TRUE(readable(watchdog.fd(), 1000ms));
  EXPECT_TRUE(watchdog.tick(/*healthy=*/true));
  EXPECT_EQ(systemd.received(), "WATCHDOG=1");
}

TEST(Watchdog, NeverFiresWhenSystemdDoesNotWatch) {
  ::unsetenv("WATCHDOG_USEC");
  Watchdog watchdog;
  EXPECT_FALSE(watchdog.interval());
  EXPECT_FALSE(readable(watchdog.fd(), 30ms));
}

}  // namespace
}  // namespace agnocast_service
