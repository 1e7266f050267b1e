// The module's trace events (kernel_module/agnocast_trace.h): tracefs lists
// every one with the fields the contract names, and a publish, receive,
// release, drop, shed, removal and a killed subscriber's teardown each show
// in the trace with the ids the UAPI returned and the pids of the processes.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdarg>
#include <cstdio>
#include <string>
#include <vector>

#include "test_util.h"

using namespace agnocast_test;

namespace {

const std::string kTracing = "/sys/kernel/tracing";
const std::string kEvents = kTracing + "/events/agnocast";
const std::vector<std::string> kEventNames = {"publish", "receive", "release",     "reclaim",
                                              "shed",    "drop",    "process_exit"};

bool exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

std::string strf(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof(buf), fmt, args);
  va_end(args);
  return buf;
}

// Writes @text to a tracefs file; false when the kernel refuses it.
bool tracefs_write(const std::string& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  return ok;
}

std::string trace() { return slurp(kTracing + "/trace"); }

bool traced(const std::string& line) { return trace().find(line) != std::string::npos; }

// Reads one value of T from @fd within 10 s; false on timeout or EOF.
template <class T>
bool read_within(int fd, T* value) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 10000) == 1 && ::read(fd, value, sizeof(*value)) == sizeof(*value);
}

class Tracepoints : public ::testing::Test {
 protected:
  void SetUp() override {
    // The test VM mounts no tracefs; its mount point is there when the kernel has one.
    if (!exists(kTracing + "/events")) {
      ASSERT_EQ(::mount("tracefs", kTracing.c_str(), "tracefs", 0, nullptr), 0) << strerror(errno);
    }
    ASSERT_TRUE(exists(kEvents)) << "no agnocast events in " << kTracing;
    dev = open_device();
    ASSERT_GE(dev, 0);
  }
  void TearDown() override {
    tracefs_write(kEvents + "/enable", "0");
    stop(child);
    reg.drop();
    close(dev);
  }
  int dev = -1;
  Registration reg;
  pid_t child = -1;
};

TEST_F(Tracepoints, TracefsListsEveryEventWithItsFields) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> fields = {
      {"publish", {"topic", "topic_id", "entry_id", "publisher_id", "pid", "bytes", "woken"}},
      {"receive",
       {"topic", "topic_id", "subscriber_id", "pid", "entry_id", "publisher_id", "entries"}},
      {"release", {"topic", "topic_id", "subscriber_id", "pid", "entry_id", "publisher_id"}},
      {"shed", {"topic", "topic_id", "subscriber_id", "pid", "entry_id", "publisher_id"}},
      {"drop", {"topic", "topic_id", "subscriber_id", "pid", "entry_id", "publisher_id", "reason"}},
      {"reclaim", {"topic", "topic_id", "entry_id", "publisher_id", "pid", "freed"}},
      {"process_exit",
       {"pid", "exited", "publishers", "subscribers", "held", "unreceived", "window",
        "reclaimable"}},
  };
  ASSERT_EQ(fields.size(), kEventNames.size());
  for (const auto& [event, names] : fields) {
    ASSERT_TRUE(exists(kEvents + "/" + event + "/enable")) << event;
    const std::string format_text = slurp(kEvents + "/" + event + "/format");
    ASSERT_NE(format_text.find("name: " + event + "\n"), std::string::npos) << format_text;
    for (const std::string& name : names)
      EXPECT_NE(format_text.find(" " + name + ";"), std::string::npos)
          << event << " has no field " << name << ":\n"
          << format_text;
  }
  EXPECT_NE(slurp(kTracing + "/available_events").find("agnocast:process_exit"), std::string::npos);
}

// One topic's life, traced: each step's event shows with the ids its call
// returned.  Depths are chosen so that each kind of event happens at a known
// step (the publisher's window is 1, so each publish pushes the one before
// out of it).
TEST_F(Tracepoints, EachEventShowsWithTheIdsTheCallsReturned) {
  const std::string topic = "/trace_events";
  const pid_t self = ::getpid();
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint pub, sub, keeper;
  ASSERT_EQ(add_publisher(dev, topic, 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, topic, 1, &sub), 0);
  ASSERT_TRUE(tracefs_write(kTracing + "/trace", ""));
  ASSERT_TRUE(tracefs_write(kEvents + "/enable", "1"));
  EXPECT_EQ(slurp(kEvents + "/enable"), "1\n");

  // publish, receive, release: one message through one subscriber.
  PublishResult e1, e2, e3, e4, e5, e6, e7;
  ASSERT_EQ(publish(dev, pub, reg.addr, &e1), 0);
  ASSERT_EQ(e1.wake, std::vector<uint32_t>{sub.id});
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr), 0);
  for (const agnocast_pool& pool : rr.pools) close(pool.fd);
  ASSERT_EQ(rr.entries.size(), 1u);
  ASSERT_EQ(rr.entries[0].entry_id, e1.entry_id);
  ASSERT_EQ(release(dev, sub, e1.entry_id), 0);
  const std::string head = strf("topic=%s topic_id=%u ", topic.c_str(), pub.handle);
  EXPECT_TRUE(traced(" publish: " + head +
                     strf("entry_id=%llu publisher_id=%u pid=%d bytes=8 woken=1\n",
                          (unsigned long long)e1.entry_id, pub.id, self)))
      << trace();
  const std::string e1_of_sub = strf("subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u",
                                     sub.id, self, (unsigned long long)e1.entry_id, pub.id);
  EXPECT_TRUE(traced(" receive: " + head + e1_of_sub + " entries=1\n")) << trace();
  EXPECT_TRUE(traced(" release: " + head + e1_of_sub + "\n")) << trace();

  // reclaim: the second publish pushes e1, released, out of the window.
  ASSERT_EQ(publish(dev, pub, reg.addr + 64, &e2), 0);
  EXPECT_TRUE(traced(" reclaim: " + head +
                     strf("entry_id=%llu publisher_id=%u pid=%d freed=0\n",
                          (unsigned long long)e1.entry_id, pub.id, self)))
      << trace();

  // drop for depth: the subscriber of depth 1 loses e2, unreceived, to e3.
  ASSERT_EQ(publish(dev, pub, reg.addr + 128, &e3), 0);
  EXPECT_TRUE(traced(" drop: " + head +
                     strf("subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u reason=depth\n",
                          sub.id, self, (unsigned long long)e2.entry_id, pub.id)))
      << trace();

  // shed: a polling subscriber keeps e4 unreceived after it left the window.
  ASSERT_EQ(add_subscriber(dev, topic, 4, &keeper, AGNOCAST_POLLING), 0);
  ASSERT_EQ(publish(dev, pub, reg.addr + 192, &e4), 0);
  ASSERT_EQ(publish(dev, pub, reg.addr + 256, &e5), 0);
  agnocast_shed shed{};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_SHED, &shed), 0);
  EXPECT_EQ(shed.shed, 1u);
  EXPECT_TRUE(traced(" shed: " + head +
                     strf("subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u\n", keeper.id,
                          self, (unsigned long long)e4.entry_id, pub.id)))
      << trace();

  // drop for removal: the polling subscriber goes with e5 unreceived.
  agnocast_remove_endpoint remove{keeper.handle, keeper.id};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &remove), 0);
  EXPECT_TRUE(traced(" drop: " + head +
                     strf("subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u reason=removed\n",
                          keeper.id, self, (unsigned long long)e5.entry_id, pub.id)))
      << trace();

  // process_exit, release, drop for removal and reclaim: a subscriber
  // process killed while it holds e6, which nothing else references once e7
  // (unreceived there) is published.
  int ids[2], held[2];
  ASSERT_EQ(::pipe2(ids, O_CLOEXEC), 0);
  ASSERT_EQ(::pipe2(held, O_CLOEXEC), 0);
  child = fork_child([&] {
    Registration child_reg;
    Endpoint child_sub;
    if (child_reg.full(dev) || add_subscriber(dev, topic, 4, &child_sub)) return 1;
    if (::write(ids[1], &child_sub.id, sizeof(child_sub.id)) != sizeof(child_sub.id)) return 2;
    for (int i = 0; i < 1000; i++) {
      ReceiveResult got;
      if (receive(dev, child_sub, &got)) return 3;
      if (!got.entries.empty()) {
        if (::write(held[1], &got.entries[0].entry_id, sizeof(uint64_t)) != sizeof(uint64_t))
          return 4;
        ::pause();
      }
      ::usleep(10000);
    }
    return 5;
  });
  ASSERT_GT(child, 0);
  uint32_t child_sub_id = 0;
  ASSERT_TRUE(read_within(ids[0], &child_sub_id));
  ASSERT_EQ(publish(dev, pub, reg.addr + 320, &e6), 0);
  uint64_t child_held = 0;
  ASSERT_TRUE(read_within(held[0], &child_held));
  ASSERT_EQ(child_held, e6.entry_id);
  ASSERT_EQ(publish(dev, pub, reg.addr + 384, &e7), 0);
  const pid_t killed = child;
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  child = -1;
  for (int fd : {ids[0], ids[1], held[0], held[1]}) close(fd);
  const std::string exit_line = strf(
      " process_exit: pid=%d exited=1 publishers=0 subscribers=1 held=1 unreceived=1 window=0 "
      "reclaimable=0\n",
      killed);
  EXPECT_TRUE(eventually([&] { return traced(exit_line); })) << trace();
  EXPECT_TRUE(traced(" receive: " + head +
                     strf("subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u entries=1\n",
                          child_sub_id, killed, (unsigned long long)e6.entry_id, pub.id)))
      << trace();
  EXPECT_TRUE(traced(" release: " + head +
                     strf("subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u\n", child_sub_id,
                          killed, (unsigned long long)e6.entry_id, pub.id)))
      << trace();
  EXPECT_TRUE(traced(" drop: " + head +
                     strf("subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u reason=removed\n",
                          child_sub_id, killed, (unsigned long long)e7.entry_id, pub.id)))
      << trace();
  EXPECT_TRUE(eventually([&] {
    return traced(" reclaim: " + head +
                  strf("entry_id=%llu publisher_id=%u pid=%d freed=0\n",
                       (unsigned long long)e6.entry_id, pub.id, self));
  })) << trace();

  // Off again: nothing more is recorded.
  ASSERT_TRUE(tracefs_write(kEvents + "/enable", "0"));
  EXPECT_EQ(slurp(kEvents + "/enable"), "0\n");
  ASSERT_TRUE(tracefs_write(kTracing + "/trace", ""));
  PublishResult e8;
  ASSERT_EQ(publish(dev, pub, reg.addr + 448, &e8), 0);
  EXPECT_FALSE(traced(" publish: ")) << trace();
}

}  // namespace
