#include "agnocast/publisher.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/limits.hpp"
#include "agnocast/node.hpp"
#include "kernel/fake_runtime.hpp"

namespace agnocast::detail {
namespace {

using PublisherTest = FakeRuntimeTest;

TEST_F(PublisherTest, GrowsItsWakeSlotsUntilEverySubscriberIsWoken) {
  Node node{"growth"};
  const std::string name = topic("growth");
  std::vector<std::uint64_t> seen(40, 0);
  std::vector<std::shared_ptr<Subscription<Counted>>> subscriptions;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    subscriptions.push_back(node.create_subscription<Counted>(
        name, QoS{1}, [&seen, i](const ipc_shared_ptr<const Counted>& m) { seen[i] = m->seq; }));
  }
  // Polling subscribers are never woken: they need no slot.
  std::vector<std::shared_ptr<PollingSubscriber<Counted>>> polling;
  for (int i = 0; i < 40; ++i)
    polling.push_back(node.create_polling_subscriber<Counted>(name, QoS{1}));
  auto publisher = node.create_publisher<Counted>(name, QoS{1});

  publish(*publisher, 1);
  // 16 slots refused (ENOBUFS), then 32, then 64 accepted.
  EXPECT_EQ(kernel().calls().publish, 3);
  for (auto& subscription : subscriptions) EXPECT_EQ(subscription->handle_wakeup(), 1U);
  for (const std::uint64_t seq : seen) EXPECT_EQ(seq, 1U);
  for (auto& subscriber : polling) {
    const auto message = subscriber->take_data();
    ASSERT_TRUE(message);
    EXPECT_EQ(message->seq, 1U);
  }
  publish(*publisher, 2);
  EXPECT_EQ(kernel().calls().publish, 4) << "the grown wake slots are kept";
}

TEST_F(PublisherTest, DepthIsBoundedByTheLimitsHeader) {
  Node node{"depths"};
  EXPECT_NO_THROW(node.create_publisher<Counted>(topic("least"), QoS{qos_depth_min}));
  EXPECT_NO_THROW(node.create_polling_subscriber<Counted>(topic("most"), QoS{qos_depth_max}));
  for (const std::size_t depth : {qos_depth_min - 1, qos_depth_max + 1}) {
    try {
      node.create_publisher<Counted>(topic("beyond"), QoS{depth});
      ADD_FAILURE() << "depth " << depth << " accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("between 1 and 1024"), std::string::npos)
          << error.what();
    }
  }
}

TEST_F(PublisherTest, FreesMessagesTheKernelReportsReclaimable) {
  Node node{"reclaim"};
  auto publisher = node.create_publisher<Counted>(topic("reclaim"), QoS{2});
  const Tlsf::Stats before = runtime().pool_stats();
  for (std::uint64_t seq = 0; seq < 100; ++seq) publish(*publisher, seq);
  // Only the publisher's depth window is still alive in the kernel; in the
  // pool also the message the last publish reclaimed, freed by the next borrow.
  EXPECT_EQ(kernel().live_entries(), 2U);
  EXPECT_EQ(runtime().pool_stats().used_blocks, before.used_blocks + 3);
  publisher->borrow_loaned_message().reset();
  EXPECT_EQ(runtime().pool_stats().used_blocks, before.used_blocks + 2);
  publish(*publisher, 100);
  publisher.reset();
  EXPECT_EQ(kernel().live_entries(), 0U);
  EXPECT_EQ(runtime().pool_stats().used_blocks, before.used_blocks);
}

TEST_F(PublisherTest, RefusesAMessageAlreadyPublished) {
  Node node{"twice"};
  auto publisher = node.create_publisher<Counted>(topic("twice"), QoS{1});
  auto message = publisher->borrow_loaned_message();
  publisher->publish(std::move(message));
  EXPECT_THROW(publisher->publish(std::move(message)), std::invalid_argument);
  EXPECT_EQ(kernel().calls().publish, 1);
}

TEST_F(PublisherTest, CountsSubscribersOfEveryKind) {
  Node node{"count"};
  const std::string name = topic("count");
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  EXPECT_EQ(publisher->get_subscription_count(), 0U);
  auto callback =
      node.create_subscription<Counted>(name, QoS{1}, [](const ipc_shared_ptr<const Counted>&) {});
  auto polling = node.create_polling_subscriber<Counted>(name, QoS{1});
  EXPECT_EQ(publisher->get_subscription_count(), 2U);
  EXPECT_EQ(callback->get_publisher_count(), 1U);
  EXPECT_EQ(polling->get_publisher_count(), 1U);
  polling.reset();
  EXPECT_EQ(publisher->get_subscription_count(), 1U);
}

TEST_F(PublisherTest, WaitForSubscribersReturnsOnceEnoughJoinedOrAtTheTimeout) {
  using namespace std::chrono_literals;
  Node node{"wait"};
  const std::string name = topic("wait");
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(publisher->wait_for_subscribers(1, 30ms));
  EXPECT_GE(std::chrono::steady_clock::now() - start, 30ms);

  std::shared_ptr<PollingSubscriber<Counted>> late;
  std::thread joiner([&] {
    std::this_thread::sleep_for(50ms);
    late = node.create_polling_subscriber<Counted>(name, QoS{1});
  });
  start = std::chrono::steady_clock::now();
  EXPECT_TRUE(publisher->wait_for_subscribers(1, 10s));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  joiner.join();
  EXPECT_TRUE(publisher->wait_for_subscribers(1, 0s));
}

}  // namespace
}  // namespace agnocast::detail
