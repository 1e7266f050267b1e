#include "agnocast/executor.hpp"

#include <gtest/gtest.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

#include "agnocast/node.hpp"
#include "kernel/fake_runtime.hpp"

namespace agnocast::detail {
namespace {

using namespace std::chrono_literals;
using ExecutorTest = FakeRuntimeTest;

template <class Condition>
bool eventually(Condition condition) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

TEST_F(ExecutorTest, SpinSomeRunsSubscriptionsCreatedAfterAddNode) {
  Node node{"late"};
  SingleThreadedExecutor executor;
  executor.add_node(node);
  const std::string name = topic("late");
  int count = 0;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  publish(*publisher, 1);
  executor.spin_some();
  EXPECT_EQ(count, 1);
  executor.spin_some();
  EXPECT_EQ(count, 1);
}

TEST_F(ExecutorTest, MultiThreadedReArmsASubscriptionWhoseCallbackThrew) {
  Node node{"rearm"};
  const std::string name = topic("rearm");
  std::atomic<int> count{0};
  auto subscription =
      node.create_subscription<Counted>(name, QoS{10}, [&](const ipc_shared_ptr<const Counted>& m) {
        ++count;
        if (m->seq == 0) throw std::runtime_error("first callback fails");
      });
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  MultiThreadedExecutor executor(2);
  executor.add_node(node);
  publish(*publisher, 0);
  EXPECT_THROW(executor.spin(), std::runtime_error);

  publish(*publisher, 1);
  std::thread spinner([&] { executor.spin(); });
  EXPECT_TRUE(eventually([&] { return count == 2; })) << "the subscription went deaf";
  executor.cancel();
  spinner.join();
}

TEST_F(ExecutorTest, MultiThreadedNeverOverlapsOneSubscriptionsCallbacks) {
  Node node{"overlap"};
  const std::string name = topic("overlap");
  std::atomic<int> running{0}, most{0}, count{0};
  auto subscription =
      node.create_subscription<Counted>(name, QoS{100}, [&](const ipc_shared_ptr<const Counted>&) {
        const int now = ++running;
        most = std::max(most.load(), now);
        std::this_thread::sleep_for(1ms);
        --running;
        ++count;
      });
  auto publisher = node.create_publisher<Counted>(name, QoS{100});
  MultiThreadedExecutor executor(4);
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  for (std::uint64_t seq = 0; seq < 50; ++seq) {
    publish(*publisher, seq);
    if (seq % 5 == 0) std::this_thread::sleep_for(1ms);
  }
  EXPECT_TRUE(eventually([&] { return count == 50; }));
  executor.cancel();
  spinner.join();
  EXPECT_EQ(most.load(), 1);
}

TEST_F(ExecutorTest, SpinOnceReturnsFalseWhenNothingIsReady) {
  Node node{"idle"};
  auto subscription = node.create_subscription<Counted>(
      topic("idle"), QoS{1}, [](const ipc_shared_ptr<const Counted>&) {});
  SingleThreadedExecutor executor;
  executor.add_node(node);
  EXPECT_TRUE(executor.spin_once(100ms)) << "the subscription's own first notification";
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(executor.spin_once(50ms));
  EXPECT_GE(std::chrono::steady_clock::now() - start, 50ms);
}

// Counts how many of some callbacks run at once.
struct Overlap {
  std::atomic<int> running{0}, most{0}, runs{0};
  void run(std::chrono::milliseconds busy) {
    const int now = ++running;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {
    }
    std::this_thread::sleep_for(busy);
    --running;
    ++runs;
  }
};

TEST_F(ExecutorTest, WallTimerFiresEveryPeriodUntilCanceled) {
  Node node{"timer"};
  std::atomic<int> ticks{0};
  auto timer = node.create_wall_timer(10ms, [&] { ++ticks; });
  SingleThreadedExecutor executor;
  executor.add_node(node);
  const auto start = std::chrono::steady_clock::now();
  while (ticks < 5) executor.spin_once(1s);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 45ms) << "five periods of 10 ms";
  timer->cancel();
  EXPECT_TRUE(timer->is_canceled());
  const int at_cancel = ticks;
  executor.spin_once(50ms);
  EXPECT_EQ(ticks, at_cancel);
  timer->reset();
  EXPECT_TRUE(executor.spin_once(1s));
  EXPECT_EQ(ticks, at_cancel + 1);
}

TEST_F(ExecutorTest, TimerRejectsANonPositivePeriod) {
  Node node{"zero"};
  EXPECT_THROW(node.create_wall_timer(0ms, [] {}), std::invalid_argument);
}

TEST_F(ExecutorTest, MutuallyExclusiveGroupRunsOneCallbackAtATime) {
  Node node{"exclusive"};
  Overlap overlap;
  auto group = node.create_callback_group(CallbackGroupType::MutuallyExclusive);
  std::vector<std::shared_ptr<Timer>> timers;
  for (int i = 0; i < 4; ++i) {
    timers.push_back(node.create_wall_timer(
        2ms, [&] { overlap.run(3ms); }, group));
  }
  MultiThreadedExecutor executor(4);
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  EXPECT_TRUE(eventually([&] { return overlap.runs >= 40; }));
  executor.cancel();
  spinner.join();
  EXPECT_EQ(overlap.most.load(), 1);
}

TEST_F(ExecutorTest, TheDefaultGroupIsMutuallyExclusive) {
  Node node{"default"};
  Overlap overlap;
  auto first = node.create_wall_timer(2ms, [&] { overlap.run(3ms); });
  auto second = node.create_wall_timer(2ms, [&] { overlap.run(3ms); });
  MultiThreadedExecutor executor(4);
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  EXPECT_TRUE(eventually([&] { return overlap.runs >= 20; }));
  executor.cancel();
  spinner.join();
  EXPECT_EQ(overlap.most.load(), 1);
}

TEST_F(ExecutorTest, ReentrantGroupRunsCallbacksInParallel) {
  Node node{"reentrant"};
  Overlap overlap;
  auto group = node.create_callback_group(CallbackGroupType::Reentrant);
  std::vector<std::shared_ptr<Timer>> timers;
  for (int i = 0; i < 3; ++i) {
    timers.push_back(node.create_wall_timer(
        5ms, [&] { overlap.run(20ms); }, group));
  }
  MultiThreadedExecutor executor(3);
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  EXPECT_TRUE(eventually([&] { return overlap.most >= 2; }));
  executor.cancel();
  spinner.join();
}

TEST_F(ExecutorTest, ExclusiveGroupsRunInParallelWithEachOther) {
  Node node{"groups"};
  Overlap overlap;
  auto first = node.create_wall_timer(
      5ms, [&] { overlap.run(20ms); },
      node.create_callback_group(CallbackGroupType::MutuallyExclusive));
  auto second = node.create_wall_timer(
      5ms, [&] { overlap.run(20ms); },
      node.create_callback_group(CallbackGroupType::MutuallyExclusive));
  MultiThreadedExecutor executor(2);
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  EXPECT_TRUE(eventually([&] { return overlap.most >= 2; }));
  executor.cancel();
  spinner.join();
}

TEST_F(ExecutorTest, AGroupSharedByTwoExecutorsKeepsBothAwake) {
  Node first_node{"first"}, second_node{"second"};
  auto group = first_node.create_callback_group(CallbackGroupType::MutuallyExclusive);
  Overlap overlap;
  std::atomic<int> first_runs{0}, second_runs{0};
  auto first = first_node.create_wall_timer(
      1ms,
      [&] {
        overlap.run(1ms);
        ++first_runs;
      },
      group);
  auto second = second_node.create_wall_timer(
      1ms,
      [&] {
        overlap.run(1ms);
        ++second_runs;
      },
      group);
  MultiThreadedExecutor first_executor(2), second_executor(2);
  first_executor.add_node(first_node);
  second_executor.add_node(second_node);
  std::thread first_spinner([&] { first_executor.spin(); });
  std::thread second_spinner([&] { second_executor.spin(); });
  // Work one executor's thread ran for the other is re-armed in the other's epoll set.
  EXPECT_TRUE(eventually([&] { return first_runs >= 50 && second_runs >= 50; }));
  first_executor.cancel();
  second_executor.cancel();
  first_spinner.join();
  second_spinner.join();
  EXPECT_EQ(overlap.most.load(), 1);
}

TEST_F(ExecutorTest, AnAddedDescriptorRunsItsCallbackWhenReadable) {
  const int fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  ASSERT_GE(fd, 0);
  int ready = 0;
  SingleThreadedExecutor executor;
  executor.add_fd(fd, [&] {
    std::uint64_t value;
    ASSERT_EQ(::read(fd, &value, sizeof value), static_cast<ssize_t>(sizeof value));
    ready += static_cast<int>(value);
  });
  EXPECT_FALSE(executor.spin_once(10ms));
  const std::uint64_t three = 3;
  ASSERT_EQ(::write(fd, &three, sizeof three), static_cast<ssize_t>(sizeof three));
  EXPECT_TRUE(executor.spin_once(1s));
  EXPECT_EQ(ready, 3);
  EXPECT_THROW(executor.add_fd(fd, [] {}), std::invalid_argument);

  executor.remove_fd(fd);
  ASSERT_EQ(::write(fd, &three, sizeof three), static_cast<ssize_t>(sizeof three));
  EXPECT_FALSE(executor.spin_once(10ms));
  EXPECT_EQ(ready, 3);
  ::close(fd);
}

TEST_F(ExecutorTest, AnExclusiveGroupsWorkIsNotLostWhenACallbackThrows) {
  Node node{"throwing"};
  auto group = node.create_callback_group(CallbackGroupType::MutuallyExclusive);
  std::atomic<int> quiet_runs{0};
  std::atomic<bool> thrown{false};
  auto failing = node.create_wall_timer(
      3ms,
      [&] {
        if (!thrown.exchange(true)) {
          std::this_thread::sleep_for(10ms);  // let the other timer queue up behind it
          throw std::runtime_error("timer failed");
        }
      },
      group);
  auto quiet = node.create_wall_timer(
      3ms, [&] { ++quiet_runs; }, group);
  MultiThreadedExecutor executor(2);
  executor.add_node(node);
  EXPECT_THROW(executor.spin(), std::runtime_error);
  std::thread spinner([&] { executor.spin(); });
  EXPECT_TRUE(eventually([&] { return quiet_runs >= 5; }));
  executor.cancel();
  spinner.join();
}

}  // namespace
}  // namespace agnocast::detail
