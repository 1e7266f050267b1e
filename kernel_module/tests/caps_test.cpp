// The module parameters that bound what one process can make the kernel
// keep: endpoints per process, held entries per subscriber, topics per
// namespace.  Reloads $AGNOCAST_MODULE with small caps and leaves it loaded
// with its defaults.
#include <sys/syscall.h>

#include "test_util.h"

using namespace agnocast_test;

namespace {

int reload(const std::string& params) {
  const char* path = std::getenv("AGNOCAST_MODULE");
  if (!path) return -ENOENT;
  eventually(
      [] { return syscall(SYS_delete_module, "agnocast", O_NONBLOCK) == 0 || errno == ENOENT; });
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return -errno;
  int ret = syscall(SYS_finit_module, fd, params.c_str(), 0) ? -errno : 0;
  close(fd);
  return ret;
}

class Caps : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ASSERT_EQ(reload("max_endpoints_per_process=4 max_held_per_subscriber=3 "
                     "max_topics_per_namespace=5"),
              0);
  }
  static void TearDownTestSuite() { EXPECT_EQ(reload(""), 0); }
  void SetUp() override {
    dev = open_device();
    ASSERT_GE(dev, 0);
    // Children of earlier tests are torn down asynchronously.
    ASSERT_TRUE(eventually([&] { return list_processes(dev).empty(); }));
    ASSERT_EQ(reg.full(dev), 0);
  }
  void TearDown() override {
    reg.drop();
    close(dev);
  }
  int dev = -1;
  Registration reg;
};

TEST(CapParameters, ZeroFailsTheLoad) {
  for (const char* param :
       {"max_endpoints_per_process=0", "max_held_per_subscriber=0", "max_topics_per_namespace=0"}) {
    EXPECT_EQ(reload(param), -EINVAL) << param;
  }
  ASSERT_EQ(reload(""), 0);
}

TEST_F(Caps, EndpointsPerProcess) {
  Endpoint ep;
  for (int i = 0; i < 4; i++) ASSERT_EQ(add_subscriber(dev, "/e", 1, &ep), 0);
  EXPECT_EQ(add_publisher(dev, "/e", 1, &ep), -EMFILE);
  EXPECT_EQ(add_subscriber(dev, "/f", 1, &ep), -EMFILE);
  // The cap is per process: another one still may.
  EXPECT_EQ(in_child([] {
              Registration r;
              Endpoint e;
              int d = open_device();
              return !r.reserve(d) && !add_publisher(d, "/e", 1, &e) ? 0 : 1;
            }),
            0);
  // Removing one makes room.
  agnocast_remove_endpoint rm{ep.handle, ep.id};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), 0);
  EXPECT_EQ(add_publisher(dev, "/e", 1, &ep), 0);
}

TEST_F(Caps, HeldEntriesPerSubscriber) {
  Endpoint pub, sub, poll;
  ASSERT_EQ(add_publisher(dev, "/h", 8, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/h", 8, &sub), 0);
  ASSERT_EQ(add_subscriber(dev, "/h", 8, &poll, AGNOCAST_POLLING), 0);
  for (int i = 0; i < 5; i++) ASSERT_EQ(publish(dev, pub, reg.addr + 64 * i), 0);

  // A receive stops at the cap; the rest waits.
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr, 8), 0);
  EXPECT_EQ(rr.entries.size(), 3u);
  EXPECT_EQ(rr.remaining, 2u);
  EXPECT_EQ(receive(dev, sub, &rr, 8), -EDQUOT);
  ASSERT_EQ(release(dev, sub, rr.entries[0].entry_id), 0);
  ReceiveResult more;
  ASSERT_EQ(receive(dev, sub, &more, 8), 0);
  EXPECT_EQ(more.entries.size(), 1u);

  // TAKE as well.
  auto take = poisoned_request<agnocast_take>();
  for (int i = 0; i < 3; i++) {
    take.topic_handle = poll.handle;
    take.subscriber_id = poll.id;
    ASSERT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), 0);
    ASSERT_EQ(take.entry_count, 1u);
    ASSERT_EQ(publish(dev, pub, reg.addr + 64 * (5 + i)), 0);
  }
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), -EDQUOT);
}

TEST_F(Caps, TopicsPerNamespace) {
  Endpoint ep;
  for (int i = 0; i < 4; i++) ASSERT_EQ(add_publisher(dev, "/t" + std::to_string(i), 1, &ep), 0);
  EXPECT_EQ(in_child([] {
              Registration r;
              Endpoint e;
              int d = open_device();
              if (r.reserve(d) || add_subscriber(d, "/t4", 1, &e)) return 1;  // the fifth topic
              if (add_subscriber(d, "/t5", 1, &e) != -ENFILE) return 2;
              return add_subscriber(d, "/t0", 1, &e) ? 3 : 0;  // an existing topic is fine
            }),
            0);
  // Another IPC namespace counts its own topics.
  EXPECT_EQ(in_child([] {
              if (unshare(CLONE_NEWIPC)) return 1;
              Registration r;
              Endpoint e;
              int d = open_device();
              return !r.reserve(d) && !add_publisher(d, "/t9", 1, &e) ? 0 : 2;
            }),
            0);
}

}  // namespace
