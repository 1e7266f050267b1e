#include "agnocast/publisher.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "agnocast/node.hpp"
#include "fake_runtime.hpp"

namespace agnocast::detail {
namespace {

using PublisherTest = FakeRuntimeTest;

void publish(Publisher<Counted>& publisher, std::uint64_t seq) {
  auto message = publisher.borrow_loaned_message();
  message->seq = seq;
  publisher.publish(std::move(message));
}

TEST_F(PublisherTest, GrowsItsWakeSlotsUntilEverySubscriberIsWoken) {
  Node node{"growth"};
  const std::string name = topic("growth");
  std::vector<std::shared_ptr<PollingSubscriber<Counted>>> subscribers;
  for (int i = 0; i < 40; ++i) {
    subscribers.push_back(node.create_polling_subscriber<Counted>(name, QoS{1}));
  }
  auto publisher = node.create_publisher<Counted>(name, QoS{1});

  publish(*publisher, 1);
  // 16 slots refused (ENOBUFS), then 32, then 64 accepted.
  EXPECT_EQ(kernel().calls().publish, 3);
  for (auto& subscriber : subscribers) {
    const auto message = subscriber->take_data();
    ASSERT_TRUE(message);
    EXPECT_EQ(message->seq, 1U);
  }
  publish(*publisher, 2);
  EXPECT_EQ(kernel().calls().publish, 4) << "the grown wake slots are kept";
}

TEST_F(PublisherTest, FreesMessagesTheKernelReportsReclaimable) {
  Node node{"reclaim"};
  auto publisher = node.create_publisher<Counted>(topic("reclaim"), QoS{2});
  const Tlsf::Stats before = runtime().pool_stats();
  for (std::uint64_t seq = 0; seq < 100; ++seq) publish(*publisher, seq);
  // Only the publisher's depth window is still alive, in the kernel and in the pool.
  EXPECT_EQ(kernel().live_entries(), 2U);
  EXPECT_EQ(runtime().pool_stats().used_blocks, before.used_blocks + 2);
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

}  // namespace
}  // namespace agnocast::detail
