#include "endpoints/notification_queue.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string>

#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"
#include "kernel/fake_runtime.hpp"

namespace agnocast::detail {
namespace {

// Unique per test run so parallel runs and leftovers never collide.
std::string test_topic(const char* what) {
  return "/agnocast_unit/" + std::string(what) + "/" + std::to_string(::getpid());
}

long pending(int fd) {
  mq_attr attributes{};
  ::mq_getattr(fd, &attributes);
  return attributes.mq_curmsgs;
}

TEST(NotificationQueue, CreatedWithTheSeedNameAndSize) {
  const std::string topic = test_topic("create");
  OwnedQueue queue(queue_name(topic, 3), 5);
  EXPECT_EQ(queue.name(), "/agnocast_unit_create_" + std::to_string(::getpid()) + "@3");
  mq_attr attributes{};
  ASSERT_EQ(::mq_getattr(queue.fd(), &attributes), 0);
  EXPECT_EQ(attributes.mq_msgsize, static_cast<long>(sizeof(MqMsgAgnocast)));
  EXPECT_EQ(attributes.mq_maxmsg, std::min(5L, system_msg_max()));
  EXPECT_TRUE(attributes.mq_flags & O_NONBLOCK);
}

TEST(NotificationQueue, ADepthOneQueueHoldsTwoSoThatAWakeUpCanDrainAfterReceiving) {
  OwnedQueue queue(queue_name(test_topic("two"), 0), 1);
  mq_attr attributes{};
  ASSERT_EQ(::mq_getattr(queue.fd(), &attributes), 0);
  EXPECT_EQ(attributes.mq_maxmsg, std::min(2L, system_msg_max()));
  EXPECT_EQ(queue.drains_after(), system_msg_max() >= 2);
}

TEST(NotificationQueue, DepthIsCappedBySystemLimit) {
  OwnedQueue queue(queue_name(test_topic("cap"), 0), 1000000);
  mq_attr attributes{};
  ASSERT_EQ(::mq_getattr(queue.fd(), &attributes), 0);
  EXPECT_EQ(attributes.mq_maxmsg, system_msg_max());
}

TEST(NotificationQueue, SendersWakeTheOwnerAndNeverBlockWhenFull) {
  const std::string topic = test_topic("wake");
  OwnedQueue queue(queue_name(topic, 1), 2);
  EXPECT_FALSE(readable(queue.fd()));
  QueueSenders senders(topic);
  for (int i = 0; i < 10; ++i) senders.notify(1);  // must return although the queue is full
  EXPECT_TRUE(readable(queue.fd()));
  EXPECT_EQ(pending(queue.fd()), 2);
  EXPECT_TRUE(queue.take_one());
  EXPECT_TRUE(queue.take_one());
  EXPECT_FALSE(readable(queue.fd()));
  EXPECT_FALSE(queue.take_one());
  senders.notify(7);  // no such queue: silently nothing
}

TEST(NotificationQueue, SelfNotificationWakes) {
  OwnedQueue queue(queue_name(test_topic("self"), 2), 1);
  queue.notify();
  EXPECT_EQ(pending(queue.fd()), 1);
  // A full queue (a depth-1 queue holds two) takes no more, and never blocks.
  queue.notify();
  queue.notify();
  EXPECT_EQ(pending(queue.fd()), std::min(2L, system_msg_max()));
}

TEST(NotificationQueue, AnyUserMayWakeButOnlyTheOwnerReadsWhateverTheUmask) {
  const std::string name = queue_name(test_topic("mode"), 3);
  const mode_t old_umask = ::umask(077);
  OwnedQueue queue(name, 1);
  ::umask(old_umask);
  struct stat st {};
  ASSERT_EQ(::fstat(queue.fd(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0622U);
}

TEST(NotificationQueue, DestructionUnlinks) {
  const std::string name = queue_name(test_topic("unlink"), 4);
  { OwnedQueue queue(name, 1); }
  EXPECT_EQ(::mq_open(name.c_str(), O_WRONLY), -1);
  EXPECT_EQ(errno, ENOENT);
}

TEST(NotificationQueue, StaleQueueOfTheSameNameIsReplaced) {
  const std::string name = queue_name(test_topic("stale"), 5);
  mq_attr attributes{};
  attributes.mq_maxmsg = 1;
  attributes.mq_msgsize = 64;
  const mqd_t stale = ::mq_open(name.c_str(), O_CREAT | O_RDWR, 0600, &attributes);
  ASSERT_NE(stale, -1);
  ::mq_close(stale);
  OwnedQueue queue(name, 1);
  ASSERT_EQ(::mq_getattr(queue.fd(), &attributes), 0);
  EXPECT_EQ(attributes.mq_msgsize, static_cast<long>(sizeof(MqMsgAgnocast)));
}

TEST(NotificationQueue, CollidingTopicsShareNamesButNeverIds) {
  // /a/b and /a_b map to one queue name per id; the kernel hands out distinct ids.
  const std::string base = test_topic("collide");
  OwnedQueue first(queue_name(base + "/x", 0), 1);
  OwnedQueue second(queue_name(base + "_x", 1), 1);
  QueueSenders to_first(base + "/x");
  to_first.notify(0);
  EXPECT_TRUE(readable(first.fd()));
  EXPECT_FALSE(readable(second.fd()));
}

TEST(NotificationQueue, LimitErrorsNameTheSysctl) {
  try {
    // An invalid name stands in for a limit: the message must still explain.
    OwnedQueue queue("/" + std::string(300, 'x') + "@0", 1);
    ADD_FAILURE();
  } catch (const QueueError& error) {
    EXPECT_NE(std::string(error.what()).find("NAME_MAX"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace agnocast::detail
