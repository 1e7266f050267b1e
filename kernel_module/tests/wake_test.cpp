// Wake-ups of AGNOCAST_WAKE_ONCE subscribers: the notifications a publisher
// sends per message, and no lost wake-up when a publisher and a subscriber
// race on separate CPUs.  The subscriber side speaks the notification
// protocol libagnocast speaks: wait for its queue, RECEIVE until `remaining`
// is 0, take one notification (after the RECEIVEs, or before them when the
// queue holds one only).
#include <gtest/gtest.h>
#include <mqueue.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include "test_util.h"

using namespace agnocast_test;

namespace {

class Wake : public ::testing::Test {
 protected:
  void SetUp() override {
    dev = open_device();
    ASSERT_GE(dev, 0);
  }
  void TearDown() override {
    reg.drop();
    close(dev);
  }
  int dev = -1;
  Registration reg;
};

// Receives everything unreceived of @sub, releasing it; returns the count.
int receive_all(int dev, Endpoint sub, uint32_t* remaining_out = nullptr) {
  int total = 0;
  for (;;) {
    ReceiveResult rr;
    if (int ret = receive(dev, sub, &rr, 8); ret) return ret;
    for (const agnocast_pool& pool : rr.pools) close(pool.fd);
    std::vector<uint64_t> ids;
    for (const agnocast_entry& entry : rr.entries) ids.push_back(entry.entry_id);
    if (!ids.empty() && release_list(dev, sub, ids)) return -1;
    total += static_cast<int>(rr.entries.size());
    if (remaining_out) *remaining_out = rr.remaining;
    if (rr.remaining == 0) return total;
  }
}

TEST_F(Wake, FlagIsForCallbackSubscribersOnly) {
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint ep;
  EXPECT_EQ(add_publisher(dev, "/wake/flags", 4, &ep, AGNOCAST_WAKE_ONCE), -EINVAL);
  EXPECT_EQ(add_subscriber(dev, "/wake/flags", 4, &ep, AGNOCAST_WAKE_ONCE | AGNOCAST_POLLING),
            -EINVAL);
  EXPECT_EQ(add_subscriber(dev, "/wake/flags", 4, &ep, AGNOCAST_WAKE_ONCE), 0);
}

// The publisher's notifications per message: 1 for a wake-once subscriber
// between two of its RECEIVEs, one per message for a plain one, none for a
// polling one.
TEST_F(Wake, OneNotificationPerWakeup) {
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint pub, once, plain, polling;
  ASSERT_EQ(add_publisher(dev, "/wake/count", 16, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/wake/count", 16, &once, AGNOCAST_WAKE_ONCE), 0);
  ASSERT_EQ(add_subscriber(dev, "/wake/count", 16, &plain), 0);
  ASSERT_EQ(add_subscriber(dev, "/wake/count", 16, &polling, AGNOCAST_POLLING), 0);

  auto sends_for = [&](int messages, uint32_t id) {
    int sends = 0;
    for (int i = 0; i < messages; i++) {
      PublishResult res;
      EXPECT_EQ(publish(dev, pub, reg.addr + 64 * i, &res), 0);
      for (uint32_t woken : res.wake) sends += woken == id;
      for (uint32_t woken : res.wake) EXPECT_NE(woken, polling.id);
    }
    return sends;
  };
  EXPECT_EQ(sends_for(5, once.id), 1);
  EXPECT_EQ(receive_all(dev, once), 5);
  EXPECT_EQ(sends_for(5, plain.id), 5);
  // The RECEIVE above cleared it: five more messages, one notification.
  EXPECT_EQ(receive_all(dev, once), 5);
  EXPECT_EQ(sends_for(3, once.id), 1);
  // A RECEIVE that finds nothing new still counts as looking.
  EXPECT_EQ(receive_all(dev, once), 3);
  EXPECT_EQ(receive_all(dev, once), 0);
  EXPECT_EQ(sends_for(1, once.id), 1);
}

struct Shared {
  std::atomic<uint64_t> received{0};
  std::atomic<uint32_t> sub_id{0};
  std::atomic<int> ready{0};
};

void pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu % static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)), &set);
  sched_setaffinity(0, sizeof(set), &set);
}

// The subscriber process: returns its exit code (0: all @messages received;
// 2: a wait timed out while entries were unreceived, i.e. a lost wake-up).
// Its queue is named like libagnocast's, topic@id (the race's topics have no
// '/' but the first).
int subscriber(Shared* shared, const std::string& topic, uint64_t messages, bool drain_after) {
  pin_to_cpu(1);
  const int dev = open_device();
  Registration r;
  Endpoint sub;
  if (dev < 0 || r.reserve(dev) || add_subscriber(dev, topic, 128, &sub, AGNOCAST_WAKE_ONCE))
    return 10;
  const std::string name = topic + "@" + std::to_string(sub.id);
  mq_attr attr{};
  attr.mq_maxmsg = drain_after ? 2 : 1;
  attr.mq_msgsize = 1;
  mq_unlink(name.c_str());
  const mqd_t queue = mq_open(name.c_str(), O_RDONLY | O_CREAT | O_EXCL | O_NONBLOCK, 0600, &attr);
  if (queue == -1) return 11;
  shared->sub_id = sub.id;
  shared->ready = 1;
  uint64_t received = 0;
  char byte;
  while (received < messages) {
    pollfd pfd{queue, POLLIN, 0};
    if (poll(&pfd, 1, 20000) != 1) {
      ReceiveResult rr;
      const int waiting = receive(dev, sub, &rr, 1) == 0 ? static_cast<int>(rr.entries.size()) : -1;
      std::fprintf(stderr, "no wake-up for 20 s after %llu of %llu messages; %d waiting\n",
                   static_cast<unsigned long long>(received),
                   static_cast<unsigned long long>(messages), waiting);
      return waiting > 0 ? 2 : 3;
    }
    if (!drain_after && mq_receive(queue, &byte, 1, nullptr) != 1) return 12;
    const int got = receive_all(dev, sub);
    if (got < 0) return 13;
    received += static_cast<uint64_t>(got);
    shared->received = received;
    if (drain_after && mq_receive(queue, &byte, 1, nullptr) != 1) return 14;
  }
  agnocast_topic_info info;
  std::vector<agnocast_publisher_info> pubs;
  std::vector<agnocast_subscriber_info> subs;
  if (topic_info(dev, topic, &info, &pubs, &subs)) return 15;
  for (const agnocast_subscriber_info& s : subs)
    if (s.id == sub.id && s.dropped) return 16;
  mq_close(queue);
  mq_unlink(name.c_str());
  return 0;
}

// One publisher and one wake-once subscriber on two CPUs: the publisher
// publishes as fast as it can (but never more than the subscriber's depth
// ahead, so nothing is dropped) and sends each notification PUBLISH asks for.
void race(int dev, Registration& reg, const std::string& topic, uint64_t messages,
          bool drain_after) {
  auto* shared = static_cast<Shared*>(
      mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0));
  ASSERT_NE(shared, MAP_FAILED);
  new (shared) Shared;
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint pub;
  ASSERT_EQ(add_publisher(dev, topic, 16, &pub), 0);
  const pid_t child = fork();
  if (child == 0) _exit(subscriber(shared, topic, messages, drain_after));
  ASSERT_GT(child, 0);
  pin_to_cpu(0);
  if (!eventually([&] { return shared->ready.load() != 0; })) {
    int status = 0;
    kill(child, SIGKILL);
    waitpid(child, &status, 0);
    FAIL() << "the subscriber did not start: exit code " << WEXITSTATUS(status);
  }
  const std::string name = topic + "@" + std::to_string(shared->sub_id.load());
  const mqd_t queue = mq_open(name.c_str(), O_WRONLY | O_NONBLOCK);
  ASSERT_NE(queue, -1);

  uint64_t sends = 0, full = 0;
  for (uint64_t i = 0; i < messages; i++) {
    while (i - shared->received.load() >= 100) sched_yield();
    PublishResult res;
    ASSERT_EQ(publish(dev, pub, reg.addr + 64 * (i % 1024), &res, 64), 0);
    ASSERT_LE(res.wake.size(), 1u);
    for (size_t k = 0; k < res.wake.size(); k++) {
      const char byte = 0;
      sends++;
      if (mq_send(queue, &byte, 1, 0) != 0) {
        ASSERT_EQ(errno, EAGAIN);
        full++;
      }
    }
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  mq_close(queue);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "2: a lost wake-up (see the subscriber's message)";
  EXPECT_EQ(shared->received.load(), messages);
  // One wake-up may carry many messages, never the other way round.  A
  // notification may find the queue full (one PUBLISH's still on its way
  // when the subscriber looked, the next one's after): a wake-up is waiting
  // then, which is all it says.
  EXPECT_LE(sends, messages);
  std::printf(
      "%llu messages, %llu notifications sent (%.3f per message), %llu found the "
      "queue full\n",
      static_cast<unsigned long long>(messages), static_cast<unsigned long long>(sends),
      static_cast<double>(sends) / static_cast<double>(messages),
      static_cast<unsigned long long>(full));
  munmap(shared, sizeof(Shared));
}

TEST_F(Wake, NoLostWakeupDrainingAfterReceiving) { race(dev, reg, "/wake_after", 10000, true); }

TEST_F(Wake, NoLostWakeupDrainingFirst) { race(dev, reg, "/wake_first", 10000, false); }

}  // namespace
