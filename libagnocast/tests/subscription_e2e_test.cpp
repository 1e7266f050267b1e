// End-to-end tests of subscriptions against the real module (run in the
// VM): ignore_local_publications within one process and across two, polling
// take semantics, and MessageInfo of another process's messages.
#include <gtest/gtest.h>

#include <agnocast/inspect.hpp>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include "e2e_support.hpp"

namespace e2e {
namespace {

using agnocast::QoS;

const agnocast::SubscriberInfo& subscriber_with_id(const agnocast::TopicInfo& info,
                                                   std::uint32_t id) {
  for (const auto& subscriber : info.subscribers) {
    if (subscriber.id == id) return subscriber;
  }
  throw std::runtime_error("no subscriber " + std::to_string(id));
}

TEST(IgnoreLocal, WithinOneProcessOwnMessagesNeverArrive) {
  const std::string topic = unique_topic("local_one");
  agnocast::Node node{"local"};
  agnocast::SubscriptionOptions options;
  options.ignore_local_publications = true;
  Received ignoring, plain;
  auto ignoring_subscription =
      node.create_subscription<Message>(topic, QoS{10}, ignoring.recorder(), options);
  auto plain_subscription = node.create_subscription<Message>(topic, QoS{10}, plain.recorder());
  auto ignoring_poller = node.create_polling_subscriber<Message>(topic, QoS{10}, options);
  auto publisher = node.create_publisher<Message>(topic, QoS{10});
  EXPECT_EQ(publisher->get_subscription_count(), 3U);
  for (std::uint64_t seq = 0; seq < 10; ++seq) publish(*publisher, seq);

  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  spin_until_quiet(executor);
  EXPECT_EQ(plain.seqs.size(), 10U);
  EXPECT_TRUE(ignoring.seqs.empty());
  EXPECT_FALSE(ignoring_poller->take_data());
  const auto info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  const auto& kernel_view = subscriber_with_id(*info, ignoring_subscription->id());
  EXPECT_EQ(kernel_view.received, 0U);
  EXPECT_EQ(kernel_view.dropped, 0U) << "own messages never took its depth";
}

TEST(IgnoreLocal, AcrossTwoProcessesOnlyTheOthersArriveAndKeepTheirPlace) {
  const std::string topic = unique_topic("local_two");
  agnocast::Node node{"local"};
  agnocast::SubscriptionOptions options;
  options.ignore_local_publications = true;
  Received ignoring;
  auto subscription =
      node.create_subscription<Message>(topic, QoS{3}, ignoring.recorder(), options);
  auto poller = node.create_polling_subscriber<Message>(topic, QoS{3}, options);

  Pipe to_parent, to_child;
  const pid_t other = fork_child([&] {
    agnocast::Node other_node{"other"};
    Received mine;
    auto own_subscription =
        other_node.create_subscription<Message>(topic, QoS{50}, mine.recorder(), options);
    auto publisher = other_node.create_publisher<Message>(topic, QoS{3});
    for (std::uint64_t seq = 1000; seq < 1003; ++seq) publish(*publisher, seq);
    to_parent.send('p');
    if (to_child.receive() != 'c') return 2;
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(other_node);
    spin_until_quiet(executor);
    // It hears the parent's 20, never its own 3.
    if (mine.seqs.size() != 20 || mine.seqs.front() != 0) return 3;
    return to_child.receive() == 'x' ? 0 : 4;
  });
  ASSERT_EQ(to_parent.receive(), 'p');
  auto publisher = node.create_publisher<Message>(topic, QoS{50});
  EXPECT_EQ(publisher->get_subscription_count(), 3U);
  EXPECT_EQ(subscription->get_publisher_count(), 2U);
  for (std::uint64_t seq = 0; seq < 20; ++seq) publish(*publisher, seq);
  to_child.send('c');

  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  spin_until_quiet(executor);
  EXPECT_EQ(ignoring.seqs, (std::vector<std::uint64_t>{1000, 1001, 1002}))
      << "twenty own messages did not push the other process's out of a depth of 3";
  const auto newest = poller->take_data();
  ASSERT_TRUE(newest);
  EXPECT_EQ(newest->seq, 1002U);
  to_child.send('x');
  EXPECT_TRUE(exited_ok(wait_child(other)));
}

TEST(Take, NewestWithinDepthThenTheSameAgainUntilANewerOne) {
  const std::string topic = unique_topic("take");
  agnocast::Node node{"poller"};
  auto poller = node.create_polling_subscriber<Message>(topic, QoS{3});
  EXPECT_FALSE(poller->take_data()) << "empty only before the first message";

  Pipe to_parent, to_child;
  const pid_t talker = fork_child([&] {
    agnocast::Node talker_node{"talker"};
    auto publisher = talker_node.create_publisher<Message>(topic, QoS{3});
    for (std::uint64_t seq = 1; seq <= 5; ++seq) publish(*publisher, seq);
    to_parent.send('a');
    if (to_child.receive() != 'b') return 2;
    publish(*publisher, 6);
    to_parent.send('c');
    return to_child.receive() == 'x' ? 0 : 3;
  });
  ASSERT_EQ(to_parent.receive(), 'a');
  const auto newest = poller->take_data();
  ASSERT_TRUE(newest);
  EXPECT_EQ(newest->seq, 5U);
  EXPECT_TRUE(chatter::verify(*newest));
  const auto again = poller->take_data();
  ASSERT_TRUE(again);
  EXPECT_EQ(again.get(), newest.get()) << "the same message, not a copy";
  EXPECT_FALSE(poller->take_new_data());

  to_child.send('b');
  ASSERT_EQ(to_parent.receive(), 'c');
  const auto fresh = poller->take_new_data();
  ASSERT_TRUE(fresh);
  EXPECT_EQ(fresh->seq, 6U);
  EXPECT_EQ(poller->take_data()->seq, 6U);
  EXPECT_EQ(newest->seq, 5U) << "an older message stays readable while held";
  to_child.send('x');
  EXPECT_TRUE(exited_ok(wait_child(talker)));
}

TEST(MessageInfo, DescribesMessagesOfAnotherProcess) {
  const std::string topic = unique_topic("info");
  agnocast::Node node{"info"};
  std::vector<agnocast::MessageInfo> infos;
  auto subscription = node.create_subscription<Message>(
      topic, QoS{10},
      [&](const Message&, const agnocast::MessageInfo& info) { infos.push_back(info); });
  const auto before = std::chrono::steady_clock::now().time_since_epoch();
  Pipe to_parent, to_child;
  const pid_t talker = fork_child([&] {
    agnocast::Node talker_node{"talker"};
    auto publisher = talker_node.create_publisher<Message>(topic, QoS{10});
    publish(*publisher, 1, 64);
    publish(*publisher, 2, 4096);
    to_parent.send(static_cast<char>(publisher->id()));
    return to_child.receive() == 'x' ? 0 : 2;
  });
  const char publisher_id = to_parent.receive();
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  spin_until_quiet(executor);
  to_child.send('x');
  EXPECT_TRUE(exited_ok(wait_child(talker)));
  ASSERT_EQ(infos.size(), 2U);
  EXPECT_EQ(infos[0].publisher_id, static_cast<std::uint32_t>(publisher_id));
  EXPECT_LT(infos[0].entry_id, infos[1].entry_id);
  EXPECT_GE(infos[0].publish_time, std::chrono::nanoseconds(before).count());
  EXPECT_LE(infos[0].publish_time, infos[1].publish_time);
  EXPECT_GE(infos[0].bytes, sizeof(Message));
  EXPECT_GE(infos[1].bytes, infos[0].bytes + 4096 - 64) << "the payload counts";
}

}  // namespace
}  // namespace e2e
