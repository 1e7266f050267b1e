#include "agnocast/executor.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <thread>

#include "agnocast/node.hpp"
#include "fake_runtime.hpp"

namespace agnocast::detail {
namespace {

using namespace std::chrono_literals;
using ExecutorTest = FakeRuntimeTest;

void publish(Publisher<Counted>& publisher, std::uint64_t seq) {
  auto message = publisher.borrow_loaned_message();
  message->seq = seq;
  publisher.publish(std::move(message));
}

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

}  // namespace
}  // namespace agnocast::detail
