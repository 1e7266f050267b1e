// End-to-end tests of executors against the real module (run in the VM):
// timers, and callback groups honoured by MultiThreadedExecutor under load.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "e2e_support.hpp"

namespace e2e {
namespace {

using agnocast::CallbackGroupType;
using agnocast::QoS;

// How many callbacks run at once, at most.
struct Overlap {
  std::atomic<int> running{0};
  std::atomic<int> most{0};
  void enter() {
    const int now = ++running;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {
    }
  }
  void leave() { --running; }
};

TEST(Timers, FireEveryPeriodAndStopWhenCanceled) {
  agnocast::Node node{"timers"};
  std::atomic<int> ticks{0};
  const auto start = std::chrono::steady_clock::now();  // the first period starts after this
  auto timer = node.create_wall_timer(20ms, [&] { ++ticks; });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  while (std::chrono::steady_clock::now() - start < 500ms) executor.spin_once(50ms);
  const int fired = ticks;
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_LE(fired, elapsed / 20ms) << "never more often than the period";
  EXPECT_GE(fired, 5) << "a slow VM may miss periods, but not most of them";

  timer->cancel();
  const auto stopped = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - stopped < 200ms) executor.spin_once(50ms);
  EXPECT_EQ(ticks, fired);
}

// A publisher in another process floods a subscription while timers tick:
// the MutuallyExclusive group never overlaps, the Reentrant one does, and no
// message is lost or reordered.
TEST(CallbackGroups, HonouredByMultiThreadedExecutorUnderLoad) {
  const std::string topic = unique_topic("groups");
  constexpr std::uint64_t count = 1000;
  agnocast::Node node{"groups"};
  auto exclusive = node.create_callback_group(CallbackGroupType::MutuallyExclusive);
  auto reentrant = node.create_callback_group(CallbackGroupType::Reentrant);
  Overlap exclusive_overlap, reentrant_overlap;
  std::vector<std::uint64_t> seqs;  // written in the exclusive group, read after spin()
  bool intact = true;
  std::atomic<std::size_t> received{0};
  std::atomic<int> exclusive_ticks{0};

  agnocast::SubscriptionOptions options;
  options.callback_group = exclusive;
  auto subscription = node.create_subscription<Message>(
      topic, QoS{1024},
      [&](const Message& message) {
        exclusive_overlap.enter();
        intact = intact && chatter::verify(message);
        seqs.push_back(message.seq);
        ++received;
        exclusive_overlap.leave();
      },
      options);
  auto exclusive_timer = node.create_wall_timer(
      2ms,
      [&] {
        exclusive_overlap.enter();
        ++exclusive_ticks;
        std::this_thread::sleep_for(1ms);
        exclusive_overlap.leave();
      },
      exclusive);
  std::vector<std::shared_ptr<agnocast::Timer>> reentrant_timers;
  for (int i = 0; i < 3; ++i) {
    reentrant_timers.push_back(node.create_wall_timer(
        5ms,
        [&] {
          reentrant_overlap.enter();
          std::this_thread::sleep_for(20ms);
          reentrant_overlap.leave();
        },
        reentrant));
  }

  Pipe to_child;
  const pid_t talker = fork_child([&] {
    agnocast::Node talker_node{"flood"};
    auto publisher = talker_node.create_publisher<Message>(topic, QoS{1024});
    if (!publisher->wait_for_subscribers(1, 30s)) return 2;
    for (std::uint64_t seq = 0; seq < count; ++seq) publish(*publisher, seq, 1024);
    return to_child.receive() == 'x' ? 0 : 3;
  });

  agnocast::MultiThreadedExecutor executor(4);
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (received < count && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
  }
  executor.cancel();
  spinner.join();
  to_child.send('x');
  EXPECT_TRUE(exited_ok(wait_child(talker)));

  ASSERT_EQ(seqs.size(), count);
  for (std::uint64_t seq = 0; seq < count; ++seq) ASSERT_EQ(seqs[seq], seq);
  EXPECT_TRUE(intact);
  EXPECT_GT(exclusive_ticks.load(), 0);
  EXPECT_EQ(exclusive_overlap.most.load(), 1);
  EXPECT_GE(reentrant_overlap.most.load(), 2);
}

}  // namespace
}  // namespace e2e
