// End-to-end tests of libagnocast against the real module (run in the VM).
#include <dirent.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>

#include <agnocast/access_policy.hpp>
#include <agnocast/inspect.hpp>
#include <algorithm>
#include <map>
#include <numeric>
#include <set>
#include <thread>
#include <tuple>

#include "e2e_support.hpp"

namespace e2e {
namespace {

using agnocast::QoS;

std::set<std::string> queue_files() {
  std::set<std::string> names;
  if (DIR* dir = ::opendir("/dev/mqueue")) {
    while (dirent* entry = ::readdir(dir)) {
      if (entry->d_name[0] != '.') names.insert(entry->d_name);
    }
    ::closedir(dir);
  }
  return names;
}

bool has_topic(const std::string& topic) {
  const auto topics = agnocast::list_topics();
  return std::any_of(topics.begin(), topics.end(),
                     [&](const auto& summary) { return summary.name == topic; });
}

TEST(Payload, SizesFromZeroTo64MiBArriveIntact) {
  const std::string topic = unique_topic("payload");
  const std::vector<std::size_t> sizes{0, 1, 7, 8, 9, 4096, 65537, 1 << 20, 16 << 20, 64 << 20};
  agnocast::Node node{"payload_listener"};
  std::vector<std::size_t> received_sizes;
  int corrupt = 0;
  auto subscription = node.create_subscription<Message>(
      topic, QoS{16}, [&](const agnocast::ipc_shared_ptr<const Message>& message) {
        if (!chatter::verify(*message) || message->seq != received_sizes.size()) ++corrupt;
        received_sizes.push_back(message->payload.size());
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  Pipe done;
  const pid_t talker = fork_child([&] {
    agnocast::Node talker_node{"payload_talker"};
    auto publisher = talker_node.create_publisher<Message>(topic, QoS{16});
    for (std::size_t i = 0; i < sizes.size(); ++i) publish(*publisher, i, sizes[i]);
    return done.receive(180s) ? 0 : 1;
  });
  EXPECT_TRUE(spin_until(
      executor, [&] { return received_sizes.size() == sizes.size() || corrupt; }, 180s));
  done.send();
  EXPECT_TRUE(exited_ok(wait_child(talker)));
  EXPECT_EQ(corrupt, 0);
  EXPECT_EQ(received_sizes, sizes);
}

TEST(Fanout, OnePublisherToThreeSubscriberProcesses) {
  const std::string topic = unique_topic("one_to_many");
  constexpr std::uint64_t count = 40;
  Pipe ready;
  std::vector<pid_t> listeners;
  for (int i = 0; i < 3; ++i) {
    listeners.push_back(fork_child([&] {
      agnocast::Node node{"listener"};
      Received received;
      auto subscription = node.create_subscription<Message>(topic, QoS{64}, received.recorder());
      agnocast::SingleThreadedExecutor executor;
      executor.add_node(node);
      ready.send();
      if (!spin_until(
              executor, [&] { return received.seqs.size() >= count; }, 60s))
        return 2;
      for (std::uint64_t i = 0; i < count; ++i) {
        if (received.seqs[i] != i) return 3;
      }
      return received.intact ? 0 : 4;
    }));
  }
  for (int i = 0; i < 3; ++i) ASSERT_EQ(ready.receive(), 'x');
  agnocast::Node node{"talker"};
  auto publisher = node.create_publisher<Message>(topic, QoS{64});
  for (std::uint64_t i = 0; i < count; ++i) publish(*publisher, i, 1000);
  for (pid_t listener : listeners) EXPECT_TRUE(exited_ok(wait_child(listener)));
}

TEST(Fanout, ThreePublisherProcessesToOneSubscriber) {
  const std::string topic = unique_topic("many_to_one");
  constexpr std::uint64_t per_publisher = 30;
  agnocast::Node node{"listener"};
  std::map<std::uint64_t, std::vector<std::uint64_t>> by_publisher;
  int corrupt = 0;
  std::size_t total = 0;
  auto subscription = node.create_subscription<Message>(
      topic, QoS{128}, [&](const agnocast::ipc_shared_ptr<const Message>& message) {
        if (!chatter::verify(*message)) ++corrupt;
        by_publisher[message->seq / 1000].push_back(message->seq % 1000);
        ++total;
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  Pipe done;
  std::vector<pid_t> talkers;
  for (std::uint64_t k = 1; k <= 3; ++k) {
    talkers.push_back(fork_child([&, k] {
      agnocast::Node talker_node{"talker" + std::to_string(k)};
      auto publisher = talker_node.create_publisher<Message>(topic, QoS{64});
      for (std::uint64_t i = 0; i < per_publisher; ++i) publish(*publisher, k * 1000 + i, 512);
      return done.receive() ? 0 : 1;
    }));
  }
  EXPECT_TRUE(spin_until(
      executor, [&] { return total >= 3 * per_publisher; }, 60s));
  for (int i = 0; i < 3; ++i) done.send();
  for (pid_t talker : talkers) EXPECT_TRUE(exited_ok(wait_child(talker)));
  EXPECT_EQ(corrupt, 0);
  std::vector<std::uint64_t> in_order(per_publisher);
  std::iota(in_order.begin(), in_order.end(), 0);
  for (std::uint64_t k = 1; k <= 3; ++k) EXPECT_EQ(by_publisher[k], in_order) << "publisher " << k;
}

// publisher depth, subscriber depth, publisher transient-local, subscriber
// transient-local, publisher created first, polling subscriber.
using QosCase = std::tuple<int, int, bool, bool, bool, bool>;

class QosMatrix : public ::testing::TestWithParam<QosCase> {};

// What a callback subscriber must receive when it reads only after everything
// was published: messages 0..4 before it joined (publisher first) or none,
// then 5..9 (or 0..9 when it joined first); a subscriber keeps its newest
// `depth` unreceived messages; a late transient-local subscriber of a
// transient-local publisher starts with the newest of those still in the
// publisher's window, at most its own depth.
std::vector<std::uint64_t> expected_callback_messages(const QosCase& c) {
  const auto [pub_depth, sub_depth, pub_tl, sub_tl, pub_first, polling] = c;
  std::vector<std::uint64_t> unreceived;
  std::uint64_t first_live = 0;
  if (pub_first) {
    if (pub_tl && sub_tl) {
      const int kept = std::min({pub_depth, sub_depth, 5});
      for (int seq = 5 - kept; seq < 5; ++seq) unreceived.push_back(seq);
    }
    first_live = 5;
  }
  for (std::uint64_t seq = first_live; seq < 10; ++seq) unreceived.push_back(seq);
  if (unreceived.size() > static_cast<std::size_t>(sub_depth)) {
    unreceived.erase(unreceived.begin(), unreceived.end() - sub_depth);
  }
  return unreceived;
}

TEST_P(QosMatrix, DeliversExactlyTheExpectedMessages) {
  const auto [pub_depth, sub_depth, pub_tl, sub_tl, pub_first, polling] = GetParam();
  const std::string topic = unique_topic("qos");
  QoS sub_qos{static_cast<std::size_t>(sub_depth)};
  if (sub_tl) sub_qos.transient_local();

  agnocast::Node node{"qos_listener"};
  std::vector<std::uint64_t> received;
  bool intact = true;
  std::shared_ptr<agnocast::Subscription<Message>> subscription;
  std::shared_ptr<agnocast::PollingSubscriber<Message>> poller;
  auto subscribe = [&] {
    if (polling) {
      poller = node.create_polling_subscriber<Message>(topic, sub_qos);
    } else {
      subscription = node.create_subscription<Message>(
          topic, sub_qos, [&](const agnocast::ipc_shared_ptr<const Message>& message) {
            intact = intact && chatter::verify(*message);
            received.push_back(message->seq);
          });
    }
  };
  auto take_seq = [&]() -> std::int64_t {
    auto message = poller->take_data();
    if (!message) return -1;
    intact = intact && chatter::verify(*message);
    return static_cast<std::int64_t>(message->seq);
  };

  Pipe to_child, to_parent;
  if (!pub_first) subscribe();
  const pid_t talker = fork_child([&] {
    agnocast::Node talker_node{"qos_talker"};
    QoS pub_qos{static_cast<std::size_t>(pub_depth)};
    if (pub_tl) pub_qos.transient_local();
    auto publisher = talker_node.create_publisher<Message>(topic, pub_qos);
    std::uint64_t seq = 0;
    if (pub_first) {
      for (; seq < 5; ++seq) publish(*publisher, seq);
    }
    to_parent.send('a');
    if (to_child.receive() != 'b') return 1;
    for (; seq < 10; ++seq) publish(*publisher, seq);
    to_parent.send('d');
    return to_child.receive() == 'x' ? 0 : 1;
  });
  ASSERT_EQ(to_parent.receive(), 'a');
  if (pub_first) subscribe();
  if (polling) {
    const std::int64_t early = take_seq();
    EXPECT_EQ(early, pub_first && pub_tl && sub_tl ? 4 : -1) << "before the live messages";
  }
  to_child.send('b');
  ASSERT_EQ(to_parent.receive(), 'd');
  if (polling) {
    EXPECT_EQ(take_seq(), 9);
    EXPECT_EQ(take_seq(), 9) << "take_data gives the newest again while nothing newer arrives";
    EXPECT_FALSE(poller->take_new_data()) << "nothing new after the newest";
  } else {
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    spin_until_quiet(executor);
    EXPECT_EQ(received, expected_callback_messages(GetParam()));
  }
  EXPECT_TRUE(intact);
  to_child.send('x');
  EXPECT_TRUE(exited_ok(wait_child(talker)));
}

std::string qos_case_name(const ::testing::TestParamInfo<QosCase>& info) {
  const auto [pub_depth, sub_depth, pub_tl, sub_tl, pub_first, polling] = info.param;
  return "pub" + std::to_string(pub_depth) + (pub_tl ? "tl" : "") + "_sub" +
         std::to_string(sub_depth) + (sub_tl ? "tl" : "") +
         (pub_first ? "_pubfirst" : "_subfirst") + (polling ? "_polling" : "_callback");
}

INSTANTIATE_TEST_SUITE_P(All, QosMatrix,
                         ::testing::Combine(::testing::Values(1, 10), ::testing::Values(1, 10),
                                            ::testing::Bool(), ::testing::Bool(), ::testing::Bool(),
                                            ::testing::Bool()),
                         qos_case_name);

TEST(Protection, WritingIntoAReceivedMessageFaults) {
  const std::string topic = unique_topic("readonly");
  agnocast::Node node{"talker"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1}.transient_local());
  publish(*publisher, 1, 4096);
  const pid_t writer = fork_child([&] {
    agnocast::Node reader{"writer"};
    auto poller = reader.create_polling_subscriber<Message>(topic, QoS{1}.transient_local());
    auto message = poller->take_data();
    if (!message || !chatter::verify(*message)) return 2;
    const_cast<Message&>(*message).seq = 5;  // must fault
    return 3;
  });
  const int status = wait_child(writer);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit code " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGSEGV);
}

TEST(Protection, HeldMessagesNeverChangeWhileThePublisherGoesOn) {
  const std::string topic = unique_topic("held");
  Pipe to_child, to_parent;
  const pid_t holder = fork_child([&] {
    agnocast::Node node{"holder"};
    std::vector<agnocast::ipc_shared_ptr<const Message>> held;
    std::size_t seen = 0;
    auto subscription = node.create_subscription<Message>(
        topic, QoS{10}, [&](const agnocast::ipc_shared_ptr<const Message>& message) {
          if (held.size() < 5) held.push_back(message);
          ++seen;
        });
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    to_parent.send('r');
    if (!spin_until(executor, [&] { return held.size() == 5; })) return 2;
    to_parent.send('h');
    if (to_child.receive() != 'd') return 3;
    spin_until_quiet(executor);
    for (std::uint64_t i = 0; i < held.size(); ++i) {
      if (held[i]->seq != i || !chatter::verify(*held[i])) return 4;
    }
    return seen > 5 ? 0 : 5;
  });
  ASSERT_EQ(to_parent.receive(), 'r');
  agnocast::Node node{"talker"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  for (std::uint64_t seq = 0; seq < 5; ++seq) publish(*publisher, seq, 8192);
  ASSERT_EQ(to_parent.receive(), 'h');
  // Depth 1: everything not held is reclaimed and its memory reused at once.
  for (std::uint64_t seq = 5; seq < 205; ++seq) publish(*publisher, seq, 8192);
  to_child.send('d');
  EXPECT_TRUE(exited_ok(wait_child(holder)));
}

TEST(Isolation, AnotherIpcNamespaceSeesOnlyItsOwnTopics) {
  const std::string topic = unique_topic("namespace");
  agnocast::Node node{"outside"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  auto subscription = node.create_subscription<Message>(
      topic, QoS{1}, [](const agnocast::ipc_shared_ptr<const Message>&) {});
  const std::string outside_queue = subscription->queue_name().substr(1);
  ASSERT_TRUE(queue_files().contains(outside_queue));

  const pid_t inside = fork_child([&] {
    if (::unshare(CLONE_NEWIPC | CLONE_NEWNS) != 0) return 2;
    // A private mount tree, and the new namespace's own mqueue filesystem.
    if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) return 3;
    if (::mount("mqueue", "/dev/mqueue", "mqueue", 0, nullptr) != 0) return 4;
    if (has_topic(topic)) return 5;
    if (queue_files().contains(outside_queue)) return 6;
    agnocast::Node inner{"inside"};
    std::uint64_t got = 0;
    auto inner_subscription = inner.create_subscription<Message>(
        topic, QoS{1},
        [&](const agnocast::ipc_shared_ptr<const Message>& message) { got = message->seq; });
    auto inner_publisher = inner.create_publisher<Message>(topic, QoS{1});
    publish(*inner_publisher, 77);
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(inner);
    if (!spin_until(executor, [&] { return got == 77; })) return 7;
    const auto info = agnocast::topic_info(topic);
    return info && info->publishers.size() == 1 && info->subscribers.size() == 1 ? 0 : 8;
  });
  EXPECT_TRUE(exited_ok(wait_child(inside))) << WEXITSTATUS(wait_child(inside));
  const auto info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->publishers.size(), 1U);
  EXPECT_EQ(info->subscribers.size(), 1U);
}

TEST(Naming, CollidingQueueNamesStillDeliverEachTopicToItsOwn) {
  const std::string base = unique_topic("collide");
  const std::string slash = base + "/b", underscore = base + "_b";
  agnocast::Node node{"listener"};
  std::vector<std::uint64_t> on_slash, on_underscore;
  auto first = node.create_subscription<Message>(
      slash, QoS{10},
      [&](const agnocast::ipc_shared_ptr<const Message>& m) { on_slash.push_back(m->seq); });
  auto second = node.create_subscription<Message>(
      underscore, QoS{10},
      [&](const agnocast::ipc_shared_ptr<const Message>& m) { on_underscore.push_back(m->seq); });
  EXPECT_NE(first->queue_name(), second->queue_name());
  Pipe done;
  const pid_t talker = fork_child([&] {
    agnocast::Node talker_node{"talker"};
    auto to_slash = talker_node.create_publisher<Message>(slash, QoS{10});
    auto to_underscore = talker_node.create_publisher<Message>(underscore, QoS{10});
    for (std::uint64_t i = 0; i < 5; ++i) {
      publish(*to_slash, 100 + i);
      publish(*to_underscore, 200 + i);
    }
    return done.receive() ? 0 : 1;
  });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  EXPECT_TRUE(
      spin_until(executor, [&] { return on_slash.size() == 5 && on_underscore.size() == 5; }));
  spin_until_quiet(executor);
  done.send();
  EXPECT_TRUE(exited_ok(wait_child(talker)));
  EXPECT_EQ(on_slash, (std::vector<std::uint64_t>{100, 101, 102, 103, 104}));
  EXPECT_EQ(on_underscore, (std::vector<std::uint64_t>{200, 201, 202, 203, 204}));
}

TEST(Naming, BadNamesAndDepthsAreRefusedWithoutLeftovers) {
  agnocast::Node node{"bad"};
  const auto queues_before = queue_files();
  const std::string too_long = "/" + std::string(agnocast::topic_name_max, 'x');
  for (const std::string& name : {std::string("chatter"), std::string("/a//b"), std::string("/a/"),
                                  std::string("/a-b"), std::string("/"), too_long}) {
    EXPECT_THROW(node.create_publisher<Message>(name, QoS{1}), std::invalid_argument) << name;
    EXPECT_THROW(node.create_subscription<Message>(
                     name, QoS{1}, [](const agnocast::ipc_shared_ptr<const Message>&) {}),
                 std::invalid_argument)
        << name;
    EXPECT_THROW(node.create_polling_subscriber<Message>(name, QoS{1}), std::invalid_argument)
        << name;
  }
  try {
    node.create_publisher<Message>(too_long, QoS{1});
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("NAME_MAX"), std::string::npos);
  }
  const std::string topic = unique_topic("bad_depth");
  EXPECT_THROW(node.create_publisher<Message>(topic, QoS{0}), std::invalid_argument);
  EXPECT_THROW(node.create_polling_subscriber<Message>(topic, QoS{100000}), std::invalid_argument);
  EXPECT_THROW(agnocast::Node{std::string(200, 'n')}, std::invalid_argument);
  EXPECT_FALSE(has_topic(topic));
  EXPECT_EQ(queue_files(), queues_before);
}

TEST(Lifecycle, DestroyingEndpointsRemovesKernelStateAndQueues) {
  const std::string topic = unique_topic("lifecycle");
  agnocast::Node node{"lifecycle"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  auto subscription = node.create_subscription<Message>(
      topic, QoS{1}, [](const agnocast::ipc_shared_ptr<const Message>&) {});
  auto poller = node.create_polling_subscriber<Message>(topic, QoS{1});
  const std::string queue = subscription->queue_name();
  EXPECT_EQ(queue, agnocast::queue_name(topic, subscription->id()));
  EXPECT_TRUE(queue_files().contains(queue.substr(1)));
  auto info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->publishers.size(), 1U);
  EXPECT_EQ(info->subscribers.size(), 2U);
  EXPECT_EQ(info->publishers[0].node, "lifecycle");
  EXPECT_EQ(info->publishers[0].pid, ::getpid());

  subscription.reset();
  EXPECT_FALSE(queue_files().contains(queue.substr(1)));
  poller.reset();
  info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->subscribers.size(), 0U);
  publisher.reset();
  EXPECT_FALSE(has_topic(topic));
}

TEST(Lifecycle, AHeldMessageKeepsItsSubscriberUntilReleased) {
  const std::string topic = unique_topic("held_after_destroy");
  agnocast::Node node{"keeper"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  agnocast::ipc_shared_ptr<const Message> kept;
  auto subscription = node.create_subscription<Message>(
      topic, QoS{1}, [&](const agnocast::ipc_shared_ptr<const Message>& m) { kept = m; });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  publish(*publisher, 3, 256);
  ASSERT_TRUE(spin_until(executor, [&] { return static_cast<bool>(kept); }));
  subscription.reset();
  for (std::uint64_t seq = 4; seq < 50; ++seq) publish(*publisher, seq, 256);
  EXPECT_EQ(kept->seq, 3U);
  EXPECT_TRUE(chatter::verify(*kept));
  kept.reset();
  const auto info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->subscribers.size(), 0U);
}

// A publisher dies and the next one gets its pool slot while the subscriber
// lives on: the subscriber is handed the new pool, replaces its view of the
// old one, and reads every new message whole.
TEST(Lifecycle, ASubscriberReadsTheNextPoolOfADeadPublishersSlot) {
  const std::string topic = unique_topic("slot_reuse");
  agnocast::Node node{"survivor"};
  Received received;
  auto subscription = node.create_subscription<Message>(topic, QoS{64}, received.recorder());
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  auto pools_we_map = [] {
    for (const auto& process : agnocast::list_processes()) {
      if (process.pid == ::getpid()) return process.pools_mapped;
    }
    return ~0U;
  };
  auto pool_of = [](pid_t pid) -> std::uint64_t {
    for (const auto& process : agnocast::list_processes()) {
      if (process.pid == pid) return process.pool_addr;
    }
    return 0;
  };
  std::vector<std::uint64_t> pool_addresses;
  for (std::uint64_t first : {0U, 100U}) {
    Pipe published, finish;
    const std::size_t expected = received.seqs.size() + 10;
    const pid_t talker = fork_child([&] {
      agnocast::Node talker_node{"talker"};
      auto publisher = talker_node.create_publisher<Message>(topic, QoS{16});
      for (std::uint64_t seq = first; seq < first + 10; ++seq) publish(*publisher, seq, 4096);
      published.send();
      return finish.receive() == 'x' ? 0 : 1;
    });
    ASSERT_EQ(published.receive(), 'x');
    pool_addresses.push_back(pool_of(talker));
    ASSERT_TRUE(spin_until(executor, [&] { return received.seqs.size() >= expected; }));
    EXPECT_EQ(pools_we_map(), 1U);
    finish.send();
    EXPECT_TRUE(exited_ok(wait_child(talker)));
    // Its window goes with it; what our callbacks dropped goes back by the
    // deferred release while the executor spins, so its pool is freed.
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    while (pools_we_map() != 0 && std::chrono::steady_clock::now() < deadline) {
      executor.spin_once(10ms);
    }
    EXPECT_EQ(pools_we_map(), 0U);
  }
  ASSERT_EQ(pool_addresses.size(), 2U);
  EXPECT_NE(pool_addresses[0], 0U);
  EXPECT_EQ(pool_addresses[1], pool_addresses[0]);  // the same slot, a new pool
  ASSERT_EQ(received.seqs.size(), 20U);
  for (std::uint64_t i = 0; i < 10; ++i) {
    EXPECT_EQ(received.seqs[i], i);
    EXPECT_EQ(received.seqs[10 + i], 100 + i);
  }
  EXPECT_TRUE(received.intact);
}

// What a callback drops rides on the next receive; when nothing follows,
// the executor's deferred release gives it back within a few milliseconds,
// and with it the pool of a publisher that died meanwhile.
TEST(Lifecycle, ADroppedMessageAndADeadPublishersPoolGoBackWithoutAnotherMessage) {
  const std::string topic = unique_topic("deferred");
  agnocast::Node node{"dropper"};
  Received received;
  auto subscription = node.create_subscription<Message>(topic, QoS{10}, received.recorder());
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  spin_until_quiet(executor, 100ms);  // the subscription's own first notification
  auto held = [&] {
    const auto info = agnocast::topic_info(topic);
    return info && info->subscribers.size() == 1 ? info->subscribers[0].held : ~0U;
  };
  auto pools_we_map = [] {
    for (const auto& process : agnocast::list_processes()) {
      if (process.pid == ::getpid()) return process.pools_mapped;
    }
    return ~0U;
  };
  Pipe published, finish;
  const pid_t talker = fork_child([&] {
    agnocast::Node talker_node{"talker"};
    auto publisher = talker_node.create_publisher<Message>(topic, QoS{1});
    publish(*publisher, 7, 1024);
    published.send();
    return finish.receive() == 'x' ? 0 : 1;
  });
  ASSERT_EQ(published.receive(), 'x');
  ASSERT_TRUE(spin_until(executor, [&] { return received.seqs.size() == 1; }));
  EXPECT_TRUE(received.intact);
  // Dropped by the callback, it waits for a receive that will not come.
  EXPECT_EQ(held(), 1U);
  finish.send();
  EXPECT_TRUE(exited_ok(wait_child(talker)));
  EXPECT_EQ(pools_we_map(), 1U) << "the dead publisher's pool stays while we hold its message";

  const auto start = std::chrono::steady_clock::now();
  while (pools_we_map() != 0 && std::chrono::steady_clock::now() - start < 10s) {
    EXPECT_FALSE(executor.spin_once(5ms)) << "the deferred release is not a callback";
  }
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(pools_we_map(), 0U);
  // 4 ms in the library; the rest is the emulator's scheduling.
  EXPECT_LT(took, 500ms);
  EXPECT_EQ(received.seqs.size(), 1U);
}

TEST(Counters, PublishedBytesCountThePayloadFilledIn) {
  const std::string topic = unique_topic("bandwidth");
  agnocast::Node node{"counter"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  publish(*publisher, 1, 64 * 1024);
  publish(*publisher, 2, 64 * 1024);
  const auto info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  ASSERT_EQ(info->publishers.size(), 1U);
  EXPECT_EQ(info->publishers[0].published, 2U);
  EXPECT_GE(info->publishers[0].published_bytes, 2U * (64 * 1024 + sizeof(Message)));
  EXPECT_LT(info->publishers[0].published_bytes, 2U * (2 * 64 * 1024 + sizeof(Message)));
}

TEST(Executors, MultiThreadedRunsEverySubscriptionAndCancels) {
  const std::string first_topic = unique_topic("mt_a"), second_topic = unique_topic("mt_b");
  agnocast::Node node{"mt"};
  std::atomic<int> first_count{0}, second_count{0};
  auto first = node.create_subscription<Message>(
      first_topic, QoS{100},
      [&](const agnocast::ipc_shared_ptr<const Message>&) { ++first_count; });
  agnocast::MultiThreadedExecutor executor(2);
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  // Created after add_node: the executor must pick it up while spinning.
  auto second = node.create_subscription<Message>(
      second_topic, QoS{100},
      [&](const agnocast::ipc_shared_ptr<const Message>&) { ++second_count; });
  auto first_publisher = node.create_publisher<Message>(first_topic, QoS{100});
  auto second_publisher = node.create_publisher<Message>(second_topic, QoS{100});
  for (std::uint64_t i = 0; i < 50; ++i) {
    publish(*first_publisher, i);
    publish(*second_publisher, i);
  }
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while ((first_count < 50 || second_count < 50) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);
  }
  executor.cancel();
  spinner.join();
  EXPECT_EQ(first_count.load(), 50);
  EXPECT_EQ(second_count.load(), 50);
}

TEST(Executors, SigtermMakesSpinReturn) {
  Pipe ready;
  const pid_t spinner = fork_child([&] {
    agnocast::Node node{"spinner"};
    auto subscription = node.create_subscription<Message>(
        unique_topic("sigterm"), QoS{1}, [](const agnocast::ipc_shared_ptr<const Message>&) {});
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    ready.send();
    executor.spin();
    return agnocast::ok() ? 2 : 0;
  });
  ASSERT_EQ(ready.receive(), 'x');
  std::this_thread::sleep_for(200ms);
  ::kill(spinner, SIGTERM);
  EXPECT_TRUE(exited_ok(wait_child(spinner, 10s)));
}

TEST(Exhaustion, LoansBeyondThePoolThrowBadAllocAndRecover) {
  const std::string topic = unique_topic("loans");
  agnocast::Node node{"hoarder"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  std::vector<agnocast::ipc_shared_ptr<Message>> loans;
  try {
    for (;;) {
      auto message = publisher->borrow_loaned_message();
      message->payload.reserve(64 << 20);  // reserved, never touched: no RAM needed
      loans.push_back(std::move(message));
    }
  } catch (const std::bad_alloc& error) {
    EXPECT_NE(std::string(error.what()).find("pool_size"), std::string::npos) << error.what();
  }
  EXPECT_GT(loans.size(), 0U);
  loans.clear();
  auto message = publisher->borrow_loaned_message();
  EXPECT_NO_THROW(message->payload.reserve(64 << 20));
}

TEST(Exhaustion, MessagesHeldBySubscribersComeBackThroughReclaim) {
  const std::string topic = unique_topic("reclaim");
  Pipe to_child, to_parent;
  const pid_t holder = fork_child([&] {
    agnocast::Node node{"holder"};
    std::vector<agnocast::ipc_shared_ptr<const Message>> held;
    auto subscription = node.create_subscription<Message>(
        topic, QoS{1024},
        [&](const agnocast::ipc_shared_ptr<const Message>& m) { held.push_back(m); });
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    to_parent.send('r');
    for (;;) {
      const char command = to_child.receive();
      if (command == 'p') {  // one more was published: hold it
        const std::size_t before = held.size();
        if (!spin_until(executor, [&] { return held.size() > before; })) return 2;
        to_parent.send('h');
      } else if (command == 'x') {  // let everything go
        held.clear();
        to_parent.send('z');
      } else {
        return command == 'q' ? 0 : 3;
      }
    }
  });
  ASSERT_EQ(to_parent.receive(), 'r');
  agnocast::Node node{"producer"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  std::size_t published = 0;
  bool exhausted = false;
  while (!exhausted && published < 1000) {
    try {
      auto message = publisher->borrow_loaned_message();
      message->seq = published;
      message->payload.reserve(64 << 20);
      publisher->publish(std::move(message));
      ++published;
      to_child.send('p');
      ASSERT_EQ(to_parent.receive(), 'h');
    } catch (const std::bad_alloc&) {
      exhausted = true;
    }
  }
  EXPECT_TRUE(exhausted);
  EXPECT_GT(published, 2U);
  to_child.send('x');
  ASSERT_EQ(to_parent.receive(), 'z');
  // The subscriber let go: the next allocation reclaims and succeeds.
  auto message = publisher->borrow_loaned_message();
  EXPECT_NO_THROW(message->payload.reserve(64 << 20));
  message.reset();
  to_child.send('q');
  EXPECT_TRUE(exited_ok(wait_child(holder)));
}

// A subscriber that never receives keeps entries beyond the publisher's
// depth only until the publisher needs the memory: 200 messages of 16 MiB
// through a 1 GiB pool never fail to allocate, and the subscriber is told how
// many it lost.
TEST(Exhaustion, ASlowSubscriberCannotExhaustAPublishersPool) {
  const std::string topic = unique_topic("slow");
  Pipe to_child, to_parent;
  const pid_t sleeper = fork_child([&] {
    agnocast::Node node{"sleeper"};
    auto subscription = node.create_subscription<Message>(
        topic, QoS{1024}, [](const agnocast::ipc_shared_ptr<const Message>&) {});
    to_parent.send('r');
    return to_child.receive() == 'q' ? 0 : 2;  // never spins: receives nothing
  });
  ASSERT_EQ(to_parent.receive(), 'r');
  agnocast::Node node{"producer"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  constexpr std::uint64_t count = 200;
  for (std::uint64_t seq = 0; seq < count; ++seq) {
    auto message = publisher->borrow_loaned_message();  // throws bad_alloc if it cannot
    message->seq = seq;
    message->payload.reserve(16 << 20);  // reserved, never touched: no RAM needed
    publisher->publish(std::move(message));
  }
  const auto info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  ASSERT_EQ(info->subscribers.size(), 1U);
  const auto& slow = info->subscribers[0];
  EXPECT_GT(slow.dropped, 0U);
  EXPECT_EQ(slow.dropped + slow.unreceived, count);
  to_child.send('q');
  EXPECT_TRUE(exited_ok(wait_child(sleeper)));
}

constexpr gid_t agnocast_group = 990;  // the VM's group agnocast, which owns the device

// Runs body as uid/gid 65534 with the given supplementary groups.
int as_nobody(std::vector<gid_t> groups, const std::function<int()>& body) {
  return wait_child(fork_child([&] {
    if (::setgroups(groups.size(), groups.data()) != 0 || ::setgid(65534) != 0 ||
        ::setuid(65534) != 0) {
      return 100;
    }
    return body();
  }));
}

TEST(Access, OutsideGroupAgnocastTheErrorSaysHowToJoin) {
  const std::string topic = unique_topic("group");
  const int status = as_nobody({}, [&] {
    try {
      agnocast::Node node{"outsider"};
      auto publisher = node.create_publisher<Message>(topic, QoS{1});
      return 2;
    } catch (const agnocast::DeviceError& error) {
      const std::string what = error.what();
      return error.code() == EACCES && what.find("group agnocast") != std::string::npos &&
                     what.find("usermod -aG agnocast") != std::string::npos
                 ? 0
                 : 3;
    }
  });
  EXPECT_TRUE(exited_ok(status)) << status;
  // A member may.
  EXPECT_TRUE(exited_ok(as_nobody({agnocast_group}, [&] {
    agnocast::Node node{"member"};
    auto publisher = node.create_publisher<Message>(topic, QoS{1});
    publish(*publisher, 1, 64);
    return 0;
  })));
}

// Publisher and subscriber of different users (both in group agnocast): the
// subscriber's queue takes every wake-up whatever its umask.
TEST(Access, UsersWakeEachOthersSubscribers) {
  const std::string topic = unique_topic("users");
  Pipe to_parent;
  const pid_t listener = fork_child([&] {
    if (::setgroups(1, &agnocast_group) != 0 || ::setgid(65534) != 0 || ::setuid(65534) != 0) {
      return 100;
    }
    ::umask(077);
    agnocast::Node node{"other_user"};
    Received received;
    auto subscription = node.create_subscription<Message>(topic, QoS{10}, received.recorder());
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    to_parent.send('r');
    if (!spin_until(executor, [&] { return received.seqs.size() == 20; })) return 2;
    return received.intact ? 0 : 3;
  });
  ASSERT_EQ(to_parent.receive(), 'r');
  agnocast::Node node{"root_talker"};
  auto publisher = node.create_publisher<Message>(topic, QoS{10});
  for (std::uint64_t seq = 0; seq < 20; ++seq) {
    publish(*publisher, seq, 256);
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_TRUE(exited_ok(wait_child(listener))) << "wake-ups lost across users";
}

TEST(Access, APolicyRefusalNamesTheTopicAndTheFix) {
  const std::string allowed = unique_topic("open");
  const std::string guarded = unique_topic("guarded");
  agnocast::AccessPolicy policy;
  policy.rules.push_back({guarded, std::vector<agnocast::AccessPrincipal>{}, std::nullopt});
  agnocast::set_access_policy(policy);
  EXPECT_EQ(agnocast::access_policy(), policy);
  const int status = as_nobody({agnocast_group}, [&] {
    agnocast::Node node{"someone"};
    auto open_publisher = node.create_publisher<Message>(allowed, QoS{1});
    auto subscriber = node.create_subscription<Message>(
        guarded, QoS{1}, [](const agnocast::ipc_shared_ptr<const Message>&) {});
    try {
      auto publisher = node.create_publisher<Message>(guarded, QoS{1});
      return 2;
    } catch (const agnocast::AccessDenied& error) {
      const std::string what = error.what();
      if (what.find(guarded) == std::string::npos) return 3;
      if (what.find("access") == std::string::npos) return 4;
    }
    // Nothing is left behind by the refusal.
    const auto info = agnocast::topic_info(guarded);
    return info && info->publishers.empty() ? 0 : 5;
  });
  agnocast::set_access_policy(std::nullopt);
  EXPECT_TRUE(exited_ok(status)) << status;
  EXPECT_EQ(agnocast::access_policy(), std::nullopt);
}

// A hand-declared message with the same field names as chatter's but another
// layout: it must never be read as one.
struct LookAlike {
  std::uint32_t seq = 0;
  std::uint64_t checksum = 0;
  agnocast::vector<std::uint8_t> payload;
};

}  // namespace
}  // namespace e2e

AGNOCAST_MESSAGE(e2e::LookAlike, "chatter/msg/Message", seq, checksum, payload);

namespace e2e {
namespace {

TEST(Types, AnEndpointOfAnotherTypeIsRefusedNamingBoth) {
  const std::string topic = unique_topic("typed");
  agnocast::Node node{"typed"};
  auto publisher = node.create_publisher<Message>(topic, QoS{1});
  const auto info = agnocast::topic_info(topic);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->type_name, agnocast::message_traits<Message>::type_name);
  EXPECT_EQ(info->type_hash, agnocast::message_traits<Message>::type_hash);
  const auto schema = agnocast::topic_schema(topic);
  ASSERT_TRUE(schema);
  const auto expected = agnocast::schema_of<Message>();
  EXPECT_TRUE(std::equal(schema->begin(), schema->end(), expected.begin(), expected.end()));

  // Same name, other layout: refused in another process and in this one.
  const int status = wait_child(fork_child([&] {
    agnocast::Node other{"other"};
    try {
      auto subscription = other.create_subscription<LookAlike>(
          topic, QoS{1}, [](const agnocast::ipc_shared_ptr<const LookAlike>&) {});
      return 2;
    } catch (const agnocast::TypeMismatch& error) {
      const std::string what = error.what();
      return what.find(topic) != std::string::npos &&
                     what.find("chatter/msg/Message") != std::string::npos
                 ? 0
                 : 3;
    }
  }));
  EXPECT_TRUE(exited_ok(status)) << status;
  try {
    auto poller = node.create_polling_subscriber<std::uint64_t>(topic, QoS{1});
    ADD_FAILURE() << "a raw:8:8 subscriber joined a chatter/msg/Message topic";
  } catch (const agnocast::TypeMismatch& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("raw:8:8"), std::string::npos) << what;
    EXPECT_NE(what.find("chatter/msg/Message"), std::string::npos) << what;
  }
  // The refusals left the topic as it was, and the right type still joins.
  EXPECT_EQ(agnocast::topic_info(topic)->subscribers.size(), 0U);
  auto poller = node.create_polling_subscriber<Message>(topic, QoS{1});
  publish(*publisher, 7, 128);
  auto message = poller->take_data();
  ASSERT_TRUE(message);
  EXPECT_TRUE(chatter::verify(*message));
}

}  // namespace
}  // namespace e2e
