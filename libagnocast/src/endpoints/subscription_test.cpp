#include "agnocast/subscription.hpp"

#include <gtest/gtest.h>
#include <mqueue.h>
#include <poll.h>
#include <signal.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "agnocast/executor.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/node.hpp"
#include "kernel/fake_runtime.hpp"

// The executor's waits and the timers armed, counted: libagnocast calls
// these through the C library, which this program's definitions replace.
namespace agnocast::detail::counted_calls {
std::atomic<int> epoll_waits{0};
std::atomic<int> timer_settings{0};
}  // namespace agnocast::detail::counted_calls

extern "C" int epoll_wait(int epoll_fd, epoll_event* events, int capacity, int timeout_ms) {
  ++agnocast::detail::counted_calls::epoll_waits;
  return static_cast<int>(
      syscall(SYS_epoll_pwait, epoll_fd, events, capacity, timeout_ms, nullptr, _NSIG / 8));
}

extern "C" int timerfd_settime(int fd, int flags, const itimerspec* value, itimerspec* old) {
  ++agnocast::detail::counted_calls::timer_settings;
  return static_cast<int>(syscall(SYS_timerfd_settime, fd, flags, value, old));
}

namespace agnocast::detail {
namespace {

using SubscriptionTest = FakeRuntimeTest;

TEST_F(SubscriptionTest, OneWakeUpDeliversEveryWaitingMessageOldestFirst) {
  Node node{"drain"};
  const std::string name = topic("drain");
  std::vector<std::uint64_t> seen;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{100}, [&](const ipc_shared_ptr<const Counted>& m) { seen.push_back(m->seq); });
  auto publisher = node.create_publisher<Counted>(name, QoS{100});
  for (std::uint64_t seq = 0; seq < 70; ++seq) publish(*publisher, seq);

  EXPECT_EQ(subscription->handle_wakeup(), 70U);
  ASSERT_EQ(seen.size(), 70U);
  for (std::uint64_t seq = 0; seq < 70; ++seq) EXPECT_EQ(seen[seq], seq);
  // Full batches, then the rest: the last receive leaves none.
  constexpr int batch = static_cast<int>(Kernel::receive_entries_max);
  EXPECT_EQ(kernel().calls().receive, (70 + batch - 1) / batch);
  EXPECT_EQ(subscription->handle_wakeup(), 0U);
}

TEST_F(SubscriptionTest, EachCallbackRecordsItsDelayFromPublishForTopicDelay) {
  Node node{"delayed"};
  const std::string name = topic("delayed");
  int calls = 0;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>&) { ++calls; });
  auto polling = node.create_polling_subscriber<Counted>(name, QoS{10});
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  const auto published = std::chrono::steady_clock::now();
  for (std::uint64_t seq = 0; seq < 5; ++seq) publish(*publisher, seq);
  EXPECT_EQ(subscription->handle_wakeup(), 5U);
  const auto longest = std::chrono::steady_clock::now() - published;
  const auto delays = recorded_delays(::getpid(), name, subscription->id());
  ASSERT_TRUE(delays);
  EXPECT_EQ(delays->count, 5U);
  ASSERT_EQ(delays->newest_ns.size(), 5U);
  for (const std::int64_t delay : delays->newest_ns) {
    EXPECT_GE(delay, 0);
    EXPECT_LE(delay, std::chrono::duration_cast<std::chrono::nanoseconds>(longest).count());
  }
  // A polling subscriber has no callback, so no delay.
  EXPECT_FALSE(recorded_delays(::getpid(), name, polling->id()));
  const std::uint32_t id = subscription->id();
  subscription.reset();
  EXPECT_FALSE(recorded_delays(::getpid(), name, id));
}

TEST_F(SubscriptionTest, AWakeUpTakesOneNotificationAndReceivesOnceAtAnyDepth) {
  for (const std::uint32_t depth : {1U, 10U}) {
    Node node{"steady"};
    const std::string name = topic("steady" + std::to_string(depth));
    int count = 0;
    auto subscription = node.create_subscription<Counted>(
        name, QoS{depth}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
    auto publisher = node.create_publisher<Counted>(name, QoS{depth});
    subscription->handle_wakeup();  // the subscription's own first notification
    const int receives_before = kernel().calls().receive;

    publish(*publisher, 1);
    EXPECT_EQ(subscription->handle_wakeup(), 1U);
    EXPECT_EQ(count, 1);
    EXPECT_EQ(kernel().calls().receive - receives_before, 1) << "depth " << depth;
    EXPECT_FALSE(readable(subscription->queue_fd())) << "depth " << depth;
  }
}

long queued(int queue_fd) {
  mq_attr attributes{};
  if (::mq_getattr(queue_fd, &attributes) != 0) return -1;
  return attributes.mq_curmsgs;
}

// Publishers wake a subscriber once between two of its receives: the
// wake-up receives until nothing remains, so one notification is enough.
TEST_F(SubscriptionTest, PublishersNotifyOncePerWakeUpHoweverManyMessagesWait) {
  Node node{"wake_once"};
  const std::string name = topic("wake_once");
  int count = 0;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  subscription->handle_wakeup();  // the subscription's own first notification
  ASSERT_EQ(queued(subscription->queue_fd()), 0);

  for (std::uint64_t seq = 0; seq < 5; ++seq) publish(*publisher, seq);
  EXPECT_EQ(queued(subscription->queue_fd()), 1) << "one notification for five messages";
  EXPECT_EQ(subscription->handle_wakeup(), 5U);
  EXPECT_EQ(count, 5);
  EXPECT_EQ(queued(subscription->queue_fd()), 0);

  publish(*publisher, 5);  // after the receive: wakes it again
  EXPECT_EQ(queued(subscription->queue_fd()), 1);
  EXPECT_EQ(subscription->handle_wakeup(), 1U);
}

// Waits until the deferred release's timer expires, then runs it as the
// executor would.
bool run_deferred_release(SubscriptionBase& subscription) {
  pollfd entry{subscription.release_timer_fd(), POLLIN, 0};
  if (::poll(&entry, 1, 2000) != 1) return false;
  subscription.release_deferred();
  return true;
}

// The subscriber's system calls per message in its steady state, one message
// per wake-up: besides the executor's wait, one notification taken and one
// RECEIVE (the fake kernel counts every call), which carries the release of
// the message before; at depth 1 and 10.  The last message's release waits
// for the deferred release.
TEST_F(SubscriptionTest, SteadyStateSystemCallsPerMessageAtDepthOneAndTen) {
  for (const std::uint32_t depth : {1U, 10U}) {
    Node node{"calls"};
    const std::string name = topic("calls" + std::to_string(depth));
    int count = 0;
    auto subscription = node.create_subscription<Counted>(
        name, QoS{depth}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
    auto publisher = node.create_publisher<Counted>(name, QoS{depth});
    subscription->handle_wakeup();  // the subscription's own first notification
    constexpr int messages = 20;
    int notifications_taken = 0;
    const FakeKernel::Calls before = kernel().calls();
    for (int i = 0; i < messages; ++i) {
      publish(*publisher, static_cast<std::uint64_t>(i));
      const FakeKernel::Calls published = kernel().calls();
      const long waiting = queued(subscription->queue_fd());
      ASSERT_EQ(waiting, 1) << "depth " << depth;
      EXPECT_EQ(subscription->handle_wakeup(), 1U);
      notifications_taken += static_cast<int>(waiting - queued(subscription->queue_fd()));
      EXPECT_EQ(kernel().calls().publish, published.publish) << "the subscriber publishes nothing";
    }
    const FakeKernel::Calls after = kernel().calls();
    EXPECT_EQ(count, messages);
    const int subscriber_kernel_calls =
        (after.receive - before.receive) + (after.release - before.release) +
        (after.take - before.take) + (after.reclaim - before.reclaim) + (after.shed - before.shed);
    EXPECT_EQ(after.receive - before.receive, messages) << "depth " << depth;
    EXPECT_EQ(subscriber_kernel_calls, messages) << "depth " << depth;
    EXPECT_EQ(notifications_taken, messages) << "depth " << depth;
    EXPECT_EQ(after.released_entries - before.released_entries, messages - 1) << "depth " << depth;
    ASSERT_TRUE(run_deferred_release(*subscription));
    EXPECT_EQ(kernel().calls().release - after.release, 1) << "depth " << depth;
    EXPECT_EQ(kernel().calls().released_entries - before.released_entries, messages);
  }
}

// The same steady state driven by an executor, every system call counted:
// per message the executor's one wait, one notification taken and one
// RECEIVE carrying the previous message's release — three — at depth 1 and
// 10.  The deferred release's deadline is the wait's timeout: no timer is
// set or read, and when nothing more arrives the last message goes back
// within the bound, in one RELEASE.
TEST_F(SubscriptionTest, InAnExecutorEachMessageCostsThreeSystemCallsAtDepthOneAndTen) {
  using counted_calls::epoll_waits;
  using counted_calls::timer_settings;
  for (const std::uint32_t depth : {1U, 10U}) {
    Node node{"executor_calls"};
    const std::string name = topic("executor_calls" + std::to_string(depth));
    int count = 0;
    auto subscription = node.create_subscription<Counted>(
        name, QoS{depth}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
    auto publisher = node.create_publisher<Counted>(name, QoS{depth});
    SingleThreadedExecutor executor;
    executor.add_node(node);
    ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(1000)));  // its own notification
    publish(*publisher, 0);  // one message before: its release is waiting from then on
    ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(1000)));

    constexpr int messages = 20;
    int notifications_taken = 0;
    const FakeKernel::Calls before = kernel().calls();
    const int waits_before = epoll_waits.load();
    const int timers_before = timer_settings.load();
    for (int i = 1; i <= messages; ++i) {
      publish(*publisher, static_cast<std::uint64_t>(i));
      const long waiting = queued(subscription->queue_fd());
      ASSERT_EQ(waiting, 1) << "depth " << depth;
      ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(1000)));
      notifications_taken += static_cast<int>(waiting - queued(subscription->queue_fd()));
    }
    const FakeKernel::Calls after = kernel().calls();
    EXPECT_EQ(count, messages + 1);
    const int kernel_calls = (after.receive - before.receive) + (after.release - before.release) +
                             (after.take - before.take) + (after.reclaim - before.reclaim) +
                             (after.shed - before.shed);
    const int waits = epoll_waits.load() - waits_before;
    EXPECT_EQ(waits, messages) << "depth " << depth;
    EXPECT_EQ(kernel_calls, messages) << "depth " << depth;
    EXPECT_EQ(notifications_taken, messages) << "depth " << depth;
    EXPECT_EQ(timer_settings.load() - timers_before, 0) << "depth " << depth;
    EXPECT_LE(waits + kernel_calls + notifications_taken, 3 * messages) << "depth " << depth;
    EXPECT_EQ(after.released_entries - before.released_entries, messages) << "depth " << depth;

    // Nothing more: the wait times out at the deadline and releases the last one.
    const auto start = std::chrono::steady_clock::now();
    EXPECT_FALSE(executor.spin_once(std::chrono::milliseconds(200)));
    TopicInfo info;
    ASSERT_TRUE(kernel().topic_info(name, info));
    EXPECT_EQ(info.subscribers.at(0).held, 0U) << "depth " << depth;
    EXPECT_EQ(kernel().calls().release - after.release, 1) << "depth " << depth;
    EXPECT_EQ(timer_settings.load() - timers_before, 0) << "depth " << depth;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(1000));
  }
}

// The deadline is kept while the executor runs other work: a wait that
// other descriptors keep ending still releases in time.
TEST_F(SubscriptionTest, TheDeferredReleaseIsNotStarvedByOtherWork) {
  Node node{"starved"};
  const std::string name = topic("starved");
  auto subscription =
      node.create_subscription<Counted>(name, QoS{10}, [](const ipc_shared_ptr<const Counted>&) {});
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  SingleThreadedExecutor executor;
  executor.add_node(node);
  ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(1000)));
  publish(*publisher, 1);
  ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(1000)));
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  ASSERT_EQ(info.subscribers.at(0).held, 1U);
  // A descriptor always readable: every wait ends at once with its event.
  const int busy = ::eventfd(1, EFD_CLOEXEC);
  ASSERT_GE(busy, 0);
  int handled = 0;
  executor.add_fd(busy, [&] { ++handled; });
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(100)) {
    ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(100)));
  }
  executor.remove_fd(busy);
  ::close(busy);
  EXPECT_GT(handled, 0);
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 0U);
}

// The notification that woke a subscriber is taken after its callbacks: a
// message published meanwhile, even into a depth-1 subscription, keeps one
// queued and is delivered by the next wake-up.
TEST_F(SubscriptionTest, TheNotificationIsTakenAfterTheCallbacksAndNoneIsLost) {
  Node node{"after"};
  const std::string name = topic("after");
  std::vector<std::uint64_t> seen;
  std::vector<long> queued_in_callback;
  std::shared_ptr<Publisher<Counted>> publisher;
  std::shared_ptr<Subscription<Counted>> subscription;
  subscription =
      node.create_subscription<Counted>(name, QoS{1}, [&](const ipc_shared_ptr<const Counted>& m) {
        seen.push_back(m->seq);
        queued_in_callback.push_back(queued(subscription->queue_fd()));
        if (m->seq < 3) publish(*publisher, m->seq + 1);
      });
  publisher = node.create_publisher<Counted>(name, QoS{1});
  subscription->handle_wakeup();  // the subscription's own first notification
  ASSERT_EQ(queued(subscription->queue_fd()), 0);

  publish(*publisher, 0);
  for (int wakeups = 0; wakeups < 10 && queued(subscription->queue_fd()) > 0; ++wakeups) {
    subscription->handle_wakeup();
  }
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{0, 1, 2, 3}));
  // Each callback saw the notification that woke it still queued.
  for (const long waiting : queued_in_callback) EXPECT_GE(waiting, 1);
  EXPECT_EQ(queued(subscription->queue_fd()), 0);
  EXPECT_EQ(subscription->handle_wakeup(), 0U);
}

TEST_F(SubscriptionTest, MessagesDroppedInOneWakeUpGoBackInOneRelease) {
  Node node{"batched"};
  const std::string name = topic("batched");
  std::vector<std::uint64_t> seen;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>& m) { seen.push_back(m->seq); });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  subscription->handle_wakeup();
  const FakeKernel::Calls before = kernel().calls();

  for (std::uint64_t seq = 1; seq <= 3; ++seq) publish(*publisher, seq);
  const auto start = std::chrono::steady_clock::now();
  subscription->handle_wakeup();
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 3U) << "they wait for the next receive";
  EXPECT_EQ(kernel().calls().release, before.release);
  // Nothing else arrives: the deferred release gives them back, within the bound.
  ASSERT_TRUE(run_deferred_release(*subscription));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(500));
  const FakeKernel::Calls after = kernel().calls();
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{1, 2, 3}));
  EXPECT_EQ(after.receive - before.receive, 1);
  EXPECT_EQ(after.release - before.release, 1);
  EXPECT_EQ(after.released_entries - before.released_entries, 3);
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 0U) << "nothing stays held after the deferred release";
}

TEST_F(SubscriptionTest, MessagesDroppedInOneWakeUpRideOnTheNextReceive) {
  Node node{"riding"};
  const std::string name = topic("riding");
  int count = 0;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  subscription->handle_wakeup();
  for (std::uint64_t seq = 1; seq <= 3; ++seq) publish(*publisher, seq);
  subscription->handle_wakeup();
  const FakeKernel::Calls before = kernel().calls();
  publish(*publisher, 4);
  subscription->handle_wakeup();
  const FakeKernel::Calls after = kernel().calls();
  EXPECT_EQ(count, 4);
  EXPECT_EQ(after.receive - before.receive, 1);
  EXPECT_EQ(after.release - before.release, 0);
  EXPECT_EQ(after.released_entries - before.released_entries, 3);
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 1U);
  // The timer armed after the first wake-up still bounds the last one's wait.
  ASSERT_TRUE(run_deferred_release(*subscription));
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 0U);
  EXPECT_EQ(kernel().calls().release - after.release, 1);
}

// A callback that throws: what its wake-up received goes back at once.
TEST_F(SubscriptionTest, AThrowingCallbacksWakeUpReleasesAtOnce) {
  Node node{"throwing"};
  const std::string name = topic("throwing");
  auto subscription =
      node.create_subscription<Counted>(name, QoS{10}, [&](const ipc_shared_ptr<const Counted>& m) {
        if (m->seq == 2) throw std::runtime_error("callback failed");
      });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  subscription->handle_wakeup();
  publish(*publisher, 1);
  publish(*publisher, 2);
  const FakeKernel::Calls before = kernel().calls();
  EXPECT_THROW(subscription->handle_wakeup(), std::runtime_error);
  EXPECT_EQ(kernel().calls().release - before.release, 1);
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 0U);
}

// Driven by an executor: the deferred release runs in spin_once() without
// counting as handled work, and without anything else arriving.
TEST_F(SubscriptionTest, AnExecutorRunsTheDeferredReleaseAsHousekeeping) {
  Node node{"housekeeping"};
  const std::string name = topic("housekeeping");
  int count = 0;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{1}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  SingleThreadedExecutor executor;
  executor.add_node(node);
  ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(100)));  // its own notification
  publish(*publisher, 1);
  ASSERT_TRUE(executor.spin_once(std::chrono::milliseconds(1000)));
  EXPECT_EQ(count, 1);
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 1U);
  EXPECT_FALSE(executor.spin_once(std::chrono::milliseconds(200)));
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 0U);
}

TEST_F(SubscriptionTest, ASingleNotificationCostsOneReceive) {
  Node node{"single"};
  const std::string name = topic("single");
  int count = 0;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>&) { ++count; });
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  subscription->handle_wakeup();  // the subscription's own first notification
  const int receives_before = kernel().calls().receive;

  publish(*publisher, 1);
  EXPECT_EQ(subscription->handle_wakeup(), 1U);
  EXPECT_EQ(count, 1);
  EXPECT_EQ(kernel().calls().receive - receives_before, 1);
}

TEST_F(SubscriptionTest, AMessageIsReleasedWhenItsLastPointerGoes) {
  Node node{"hold"};
  const std::string name = topic("hold");
  std::vector<ipc_shared_ptr<const Counted>> kept;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>& m) { kept.push_back(m); });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  publish(*publisher, 1);
  publish(*publisher, 2);
  subscription->handle_wakeup();
  ASSERT_EQ(kept.size(), 2U);
  // The first left the publisher's window but is held: it must stay.
  EXPECT_EQ(kernel().live_entries(), 2U);
  EXPECT_EQ(kept[0]->seq, 1U);
  kept.erase(kept.begin());
  EXPECT_EQ(kernel().calls().release, 1);
  EXPECT_EQ(kernel().live_entries(), 1U);
}

// References go back to the subscriber for reuse: more held at once than it
// keeps spare, then reused ones, must each point to their own entry and
// release it exactly once.
TEST_F(SubscriptionTest, ReusedReferencesEachReleaseTheirOwnEntryOnce) {
  Node node{"reuse"};
  const std::string name = topic("reuse");
  std::vector<ipc_shared_ptr<const Counted>> kept;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{100}, [&](const ipc_shared_ptr<const Counted>& m) { kept.push_back(m); });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  for (std::uint64_t batch = 0; batch < 3; ++batch) {
    const int releases_before = kernel().calls().release;
    for (std::uint64_t seq = 0; seq < 40; ++seq) publish(*publisher, batch * 100 + seq);
    subscription->handle_wakeup();
    ASSERT_EQ(kept.size(), 40U);
    for (std::uint64_t seq = 0; seq < 40; ++seq) {
      EXPECT_EQ(kept[seq]->seq, batch * 100 + seq);
      EXPECT_EQ(kept[seq].use_count(), 1U);
    }
    kept.clear();
    EXPECT_EQ(kernel().calls().release - releases_before, 40);
    EXPECT_EQ(kernel().live_entries(), 1U);  // the newest, in the publisher's window
  }
}

TEST_F(SubscriptionTest, AThrowingCallbackReleasesTheRestOfItsBatchAndLosesNothingLater) {
  Node node{"throw"};
  const std::string name = topic("throw");
  std::vector<std::uint64_t> seen;
  auto subscription =
      node.create_subscription<Counted>(name, QoS{10}, [&](const ipc_shared_ptr<const Counted>& m) {
        seen.push_back(m->seq);
        if (m->seq == 1) throw std::runtime_error("callback failed");
      });
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  for (std::uint64_t seq = 0; seq < 4; ++seq) publish(*publisher, seq);

  EXPECT_THROW(subscription->handle_wakeup(), std::runtime_error);
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{0, 1}));
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 0U) << "undelivered entries of the batch are released";

  publish(*publisher, 4);
  subscription->handle_wakeup();
  EXPECT_EQ(seen.back(), 4U);
}

TEST_F(SubscriptionTest, ASubscriptionOutlivedByItsMessagesKeepsThemValid) {
  Node node{"outlive"};
  const std::string name = topic("outlive");
  ipc_shared_ptr<const Counted> kept;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>& m) { kept = m; });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  publish(*publisher, 7);
  publish(*publisher, 8);
  subscription->handle_wakeup();
  subscription.reset();
  EXPECT_EQ(kept->seq, 8U);
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.size(), 1U) << "the kernel subscriber stays while a message is held";
  kept.reset();
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_TRUE(info.subscribers.empty());
}

TEST_F(SubscriptionTest, CallbacksMayTakeTheMessageAndItsInfo) {
  Node node{"forms"};
  const std::string name = topic("forms");
  std::vector<std::uint64_t> by_reference;
  std::vector<MessageInfo> infos;
  auto plain = node.create_subscription<Counted>(
      name, QoS{10}, [&](const Counted& m) { by_reference.push_back(m.seq); });
  auto with_info = node.create_subscription<Counted>(
      name, QoS{10}, [&](const Counted& m, const MessageInfo& info) {
        EXPECT_EQ(m.seq, 5U);
        infos.push_back(info);
      });
  auto pointer_with_info = node.create_subscription<Counted>(
      name, QoS{10}, [&](const ipc_shared_ptr<const Counted>& m, const MessageInfo& info) {
        EXPECT_EQ(m->seq, 5U);
        infos.push_back(info);
      });
  auto publisher = node.create_publisher<Counted>(name, QoS{10});
  const auto before = std::chrono::steady_clock::now().time_since_epoch();
  publish(*publisher, 5);
  const auto after = std::chrono::steady_clock::now().time_since_epoch();
  plain->handle_wakeup();
  with_info->handle_wakeup();
  pointer_with_info->handle_wakeup();

  EXPECT_EQ(by_reference, std::vector<std::uint64_t>{5});
  ASSERT_EQ(infos.size(), 2U);
  for (const MessageInfo& info : infos) {
    EXPECT_EQ(info.publisher_id, publisher->id());
    EXPECT_EQ(info.bytes, sizeof(Counted));
    EXPECT_GE(info.publish_time, std::chrono::nanoseconds(before).count());
    EXPECT_LE(info.publish_time, std::chrono::nanoseconds(after).count());
  }
  EXPECT_EQ(infos[0].entry_id, infos[1].entry_id);
}

TEST_F(SubscriptionTest, IgnoringLocalPublicationsGetsOnlyOtherProcesses) {
  Node node{"local"};
  const std::string name = topic("local");
  std::vector<std::uint64_t> seen;
  SubscriptionOptions options;
  options.ignore_local_publications = true;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{2}, [&](const Counted& m) { seen.push_back(m.seq); }, options);
  auto own = node.create_publisher<Counted>(name, QoS{10});
  kernel().set_caller_pid(::getpid() + 100000);  // another process
  auto other = node.create_publisher<Counted>(name, QoS{10});
  publish(*other, 100);
  kernel().set_caller_pid(::getpid());
  for (std::uint64_t seq = 0; seq < 5; ++seq) publish(*own, seq);

  subscription->handle_wakeup();
  // Five own messages did not push the other process's out of a depth of 2.
  EXPECT_EQ(seen, std::vector<std::uint64_t>{100});
}

TEST_F(SubscriptionTest, TakeDataGivesTheNewestAgainUntilSomethingNewerArrives) {
  Node node{"take"};
  const std::string name = topic("take");
  auto poll = node.create_polling_subscriber<Counted>(name, QoS{3});
  auto publisher = node.create_publisher<Counted>(name, QoS{3});
  EXPECT_FALSE(poll->take_data()) << "empty before the first message";
  EXPECT_FALSE(poll->take_new_data());

  for (std::uint64_t seq = 1; seq <= 3; ++seq) publish(*publisher, seq);
  auto first = poll->take_data();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->seq, 3U) << "the newest within depth";
  auto again = poll->take_data();
  ASSERT_TRUE(again);
  EXPECT_EQ(again.get(), first.get()) << "the same message again";
  EXPECT_FALSE(poll->take_new_data()) << "nothing new since";

  publish(*publisher, 4);
  auto fresh = poll->take_new_data();
  ASSERT_TRUE(fresh);
  EXPECT_EQ(fresh->seq, 4U);
  EXPECT_EQ(poll->take_data()->seq, 4U);
  // Only the latest stays held for take_data(); 1..3 went back to the publisher.
  first.reset();
  again.reset();
  TopicInfo info;
  ASSERT_TRUE(kernel().topic_info(name, info));
  EXPECT_EQ(info.subscribers.at(0).held, 1U);
}

}  // namespace
}  // namespace agnocast::detail
