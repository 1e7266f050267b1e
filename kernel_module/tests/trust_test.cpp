// The security model as an attacker tries it: pools nobody else can write, the topic
// access policy, shedding for slow subscribers, exit records that are never
// dropped silently and namespace state that ends with its namespace.  Runs as
// root in the VM; attackers are forked children that drop to other users.
#include <grp.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include "test_util.h"

using namespace agnocast_test;

namespace {

constexpr uint64_t kMagic = 0x7472757374000000ull;

// A child's findings, as text through a pipe, so a failure says what failed.
class Report {
 public:
  Report() { EXPECT_EQ(pipe(fds_), 0); }
  ~Report() {
    close(fds_[0]);
    if (fds_[1] >= 0) close(fds_[1]);
  }
  // In the child.
  void fail(const std::string& what) {
    const std::string line = what + " (errno " + std::strerror(errno) + ")\n";
    (void)!write(fds_[1], line.data(), line.size());
  }
  // In the parent, after the child exited: everything it reported.
  std::string read_all() {
    close(fds_[1]);
    fds_[1] = -1;
    std::string text;
    char buf[512];
    ssize_t n;
    while ((n = read(fds_[0], buf, sizeof(buf))) > 0) text.append(buf, static_cast<size_t>(n));
    return text;
  }

 private:
  int fds_[2] = {-1, -1};
};

// Waits for a byte from the other side of @fds.
bool wait_byte(int fd) {
  char c;
  return read(fd, &c, 1) == 1;
}

class Trust : public ::testing::Test {
 protected:
  void SetUp() override {
    dev = open_device();
    ASSERT_GE(dev, 0) << strerror(errno);
  }
  void TearDown() override {
    agnocast_policy none{};
    ioc(dev, AGNOCAST_IOC_SET_POLICY, &none);
    reg.drop();
    close(dev);
  }

  int dev = -1;
  Registration reg;
};

TEST_F(Trust, DeviceIsNotWorldAccessible) {
  struct stat st;
  ASSERT_EQ(stat(AGNOCAST_DEVICE_PATH, &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0660u);
  // Another user outside the device's group cannot open it at all.
  EXPECT_EQ(in_child([&] {
              if (!become(kNobody, kNobody)) return 10;
              return open_device() < 0 && errno == EACCES ? 0 : 11;
            }),
            0);
}

// Every way another process could write a publisher's pool fails, whoever it
// is, and the publisher and its readers go on with intact messages.
TEST_F(Trust, NoOtherProcessCanWriteAPool) {
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint pub;
  ASSERT_EQ(add_publisher(dev, "/trust/pool", 4, &pub), 0);
  auto* message = static_cast<uint64_t*>(reg.map) + 8;
  const pid_t publisher = getpid();

  // attacker: 0 another user in group agnocast, 1 root (but not the owner).
  for (int attacker = 0; attacker < 2; attacker++) {
    SCOPED_TRACE(attacker ? "as root" : "as uid 65534 in group agnocast");
    message[0] = kMagic + attacker;
    Report report;
    int subscribed[2], published[2];
    ASSERT_EQ(pipe(subscribed), 0);
    ASSERT_EQ(pipe(published), 0);
    pid_t child = fork();
    if (child == 0) {
      munmap(reg.map, reg.size);  // the publisher's writable mapping, inherited
      if (attacker == 0 && !become(kNobody, kNobody, {kAgnocastGroup})) _exit(10);
      Registration r;
      Endpoint sub;
      int d = open_device();
      if (d < 0 || r.reserve(d) || add_subscriber(d, "/trust/pool", 4, &sub)) _exit(11);
      (void)!write(subscribed[1], "s", 1);
      if (!wait_byte(published[0])) _exit(12);
      ReceiveResult rr;
      if (receive(d, sub, &rr) || rr.entries.size() != 1 || rr.pools.size() != 1) _exit(13);
      const int fd = rr.pools[0].fd;
      const size_t size = rr.pools[0].size;
      auto* view = static_cast<uint64_t*>(mmap(reinterpret_cast<void*>(rr.pools[0].addr), size,
                                               PROT_READ, MAP_SHARED | MAP_FIXED_NOREPLACE, fd, 0));
      if (view == MAP_FAILED) _exit(14);
      const auto* seen = reinterpret_cast<const uint64_t*>(rr.entries[0].addr);

      // Writable descriptors: a root attacker may reopen the file (it may
      // ptrace anyone), another user may not.
      std::vector<int> writable;
      for (const std::string& path :
           {"/proc/self/fd/" + std::to_string(fd),
            "/proc/" + std::to_string(publisher) + "/fd/" + std::to_string(reg.memfd)}) {
        int w = open(path.c_str(), O_RDWR);
        if (attacker == 0 && w >= 0) report.fail("reopened " + path + " read-write");
        if (w >= 0) writable.push_back(w);
      }
      writable.push_back(fd);
      char page[4096] = {1};
      for (int w : writable) {
        const std::string name = "descriptor " + std::to_string(w);
        if (mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, w, 0) != MAP_FAILED)
          report.fail(name + ": mmap(PROT_WRITE, MAP_SHARED) succeeded");
        if (pwrite(w, page, sizeof(page), 0) >= 0) report.fail(name + ": pwrite succeeded");
        if (write(w, page, sizeof(page)) >= 0) report.fail(name + ": write succeeded");
        if (ftruncate(w, 0) == 0) report.fail(name + ": ftruncate(0) succeeded");
        if (ftruncate(w, static_cast<off_t>(size) * 2) == 0)
          report.fail(name + ": ftruncate(grow) succeeded");
        if (fallocate(w, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, 0, 1 << 20) == 0)
          report.fail(name + ": fallocate(PUNCH_HOLE) succeeded");
        if (fallocate(w, 0, static_cast<off_t>(size), 4096) == 0)
          report.fail(name + ": fallocate(grow) succeeded");
        if (fcntl(w, F_ADD_SEALS, F_SEAL_WRITE) == 0 ||
            fcntl(w, F_GET_SEALS) != static_cast<int>(AGNOCAST_POOL_SEALS))
          report.fail(name + ": seals changed");
        void* ro = mmap(nullptr, 4096, PROT_READ, MAP_SHARED, w, 0);
        if (ro == MAP_FAILED) {
          report.fail(name + ": mmap(PROT_READ) failed");
        } else {
          if (mprotect(ro, 4096, PROT_READ | PROT_WRITE) == 0)
            report.fail(name + ": mprotect(PROT_WRITE) of a new mapping succeeded");
          munmap(ro, 4096);
        }
      }
      if (mprotect(view, 4096, PROT_READ | PROT_WRITE) == 0)
        report.fail("mprotect of the read-only view to PROT_WRITE succeeded");
      if (*seen != kMagic + static_cast<uint64_t>(attacker)) report.fail("message changed");
      _exit(0);
    }
    ASSERT_TRUE(wait_byte(subscribed[0]));
    ASSERT_EQ(publish(dev, pub, reinterpret_cast<uint64_t>(message)), 0);
    (void)!write(published[1], "p", 1);
    int status = 0;
    waitpid(child, &status, 0);
    EXPECT_EQ(report.read_all(), "");
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
    for (int fd : {subscribed[0], subscribed[1], published[0], published[1]}) close(fd);

    // The owner's mapping still writes, the pool kept its size and content.
    EXPECT_EQ(message[0], kMagic + attacker);
    message[1] = kMagic;
    EXPECT_EQ(message[1], kMagic);
    struct stat st;
    ASSERT_EQ(fstat(reg.memfd, &st), 0);
    EXPECT_EQ(static_cast<uint64_t>(st.st_size), reg.size);
  }
}

struct Creds {
  uid_t uid;
  gid_t gid;
  std::vector<gid_t> groups;
};

// What ADD_PUBLISHER (publisher) or ADD_SUBSCRIBER returns for @creds.
int endpoint_as(const Creds& creds, const std::string& topic, bool publisher) {
  int fds[2];
  if (pipe(fds)) return -1000;
  pid_t child = fork();
  if (child == 0) {
    int ret = -2000;
    std::vector<gid_t> groups = creds.groups;
    groups.push_back(kAgnocastGroup);
    Registration r;
    Endpoint ep;
    if (become(creds.uid, creds.gid, groups)) {
      int d = open_device();
      if (d >= 0 && !r.reserve(d))
        ret = publisher ? add_publisher(d, topic, 1, &ep) : add_subscriber(d, topic, 1, &ep);
    }
    (void)!write(fds[1], &ret, sizeof(ret));
    _exit(0);
  }
  int ret = -3000;
  close(fds[1]);
  (void)!read(fds[0], &ret, sizeof(ret));
  close(fds[0]);
  waitpid(child, nullptr, 0);
  return ret;
}

const Creds kSafetyMember{1001, 1001, {2001}};  // in group 2001 ("safety")
const Creds kMonitor{1002, 1002, {}};           // user 1002 ("monitor")
const Creds kOutsider{1003, 1003, {}};

TEST_F(Trust, PolicyDecidesByFirstMatchingRule) {
  ASSERT_EQ(
      set_policy(dev, {{"/safety",
                        AGNOCAST_MATCH_DESCENDANTS,
                        {{group_principal(2001)}},
                        {{group_principal(2001), user_principal(1002)}}},
                       {"/cam", AGNOCAST_MATCH_CHILDREN, {{user_principal(1003)}}, std::nullopt},
                       {"/cam/front", AGNOCAST_MATCH_EXACT, {{}}, {{}}},
                       {"/status", AGNOCAST_MATCH_EXACT, {{anyone_principal()}}, {{}}}}),
      0);
  // /safety/** : the group publishes, the group and the monitor subscribe.
  EXPECT_EQ(endpoint_as(kSafetyMember, "/safety/brake", true), 0);
  EXPECT_EQ(endpoint_as(kSafetyMember, "/safety/a/b/c", false), 0);
  EXPECT_EQ(endpoint_as(kMonitor, "/safety/brake", false), 0);
  EXPECT_EQ(endpoint_as(kMonitor, "/safety/brake", true), -EACCES);
  EXPECT_EQ(endpoint_as(kOutsider, "/safety/a/b", false), -EACCES);
  // "/safety/**" does not cover "/safety" itself: the default (allow) decides.
  EXPECT_EQ(endpoint_as(kOutsider, "/safety", true), 0);
  // /cam/* : one level only; subscribe is not listed, so the default decides.
  EXPECT_EQ(endpoint_as(kOutsider, "/cam/rear", true), 0);
  EXPECT_EQ(endpoint_as(kMonitor, "/cam/rear", true), -EACCES);
  EXPECT_EQ(endpoint_as(kMonitor, "/cam/rear", false), 0);
  EXPECT_EQ(endpoint_as(kMonitor, "/cam/rear/raw", true), 0);
  // The earlier /cam/* rule wins over the exact /cam/front rule.
  EXPECT_EQ(endpoint_as(kOutsider, "/cam/front", true), 0);
  // An empty list allows nobody; anyone allows everybody.
  EXPECT_EQ(endpoint_as(kOutsider, "/status", true), 0);
  EXPECT_EQ(endpoint_as(kSafetyMember, "/status", false), -EACCES);
  // Root is not exempt.
  Registration root;
  ASSERT_EQ(root.reserve(dev), 0);
  Endpoint ep;
  EXPECT_EQ(add_subscriber(dev, "/status", 1, &ep), -EACCES);
  EXPECT_EQ(add_publisher(dev, "/status", 1, &ep), 0);
  root.drop();
}

TEST_F(Trust, PolicyDefaultDenyAndRootPatterns) {
  ASSERT_EQ(
      set_policy(dev,
                 {{"", AGNOCAST_MATCH_CHILDREN, {{group_principal(2001)}}, {{anyone_principal()}}}},
                 true),
      0);
  EXPECT_EQ(endpoint_as(kSafetyMember, "/top", true), 0);
  EXPECT_EQ(endpoint_as(kOutsider, "/top", true), -EACCES);
  EXPECT_EQ(endpoint_as(kOutsider, "/top", false), 0);
  EXPECT_EQ(endpoint_as(kSafetyMember, "/top/deeper", true), -EACCES);  // default deny
  EXPECT_EQ(endpoint_as(kSafetyMember, "/top/deeper", false), -EACCES);
  ASSERT_EQ(
      set_policy(dev, {{"", AGNOCAST_MATCH_DESCENDANTS, {{user_principal(1003)}}, std::nullopt}},
                 true),
      0);
  EXPECT_EQ(endpoint_as(kOutsider, "/top/deeper", true), 0);
  EXPECT_EQ(endpoint_as(kOutsider, "/top/deeper", false), -EACCES);
}

TEST_F(Trust, PolicyChangeKeepsExistingEndpoints) {
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/kept", 4, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/kept", 4, &sub), 0);
  ASSERT_EQ(set_policy(dev, {}, true), 0);
  Endpoint denied;
  EXPECT_EQ(add_publisher(dev, "/kept", 4, &denied), -EACCES);
  EXPECT_EQ(add_subscriber(dev, "/other", 4, &denied), -EACCES);
  // The endpoints made before still work.
  ASSERT_EQ(publish(dev, pub, reg.addr), 0);
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr), 0);
  EXPECT_EQ(rr.entries.size(), 1u);
  // Removing the policy lets everyone in again.
  agnocast_policy none{};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_SET_POLICY, &none), 0);
  EXPECT_EQ(add_publisher(dev, "/kept", 4, &denied), 0);
}

// A slow subscriber's backlog beyond the publisher's depth goes when the
// publisher needs its memory; what a subscriber holds never does.
TEST_F(Trust, ShedTakesOnlyUnheldEntriesOutsideTheWindow) {
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint pub, slow, holder;
  ASSERT_EQ(add_publisher(dev, "/shed", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/shed", 1024, &slow), 0);
  ASSERT_EQ(add_subscriber(dev, "/shed", 1024, &holder, AGNOCAST_POLLING), 0);
  for (int i = 0; i < 10; i++) ASSERT_EQ(publish(dev, pub, reg.addr + 64 * i), 0);
  // The holder takes the newest (and passes over the older ones): it holds one.
  auto take = poisoned_request<agnocast_take>();
  take.topic_handle = holder.handle;
  take.subscriber_id = holder.id;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), 0);
  ASSERT_EQ(take.entry_count, 1u);
  ASSERT_EQ(publish(dev, pub, reg.addr + 64 * 10), 0);
  ASSERT_EQ(publish(dev, pub, reg.addr + 64 * 11), 0);  // entry 10 leaves the window

  // Entries 0..10 are out of the window; the slow one waits for all of them.
  auto shed = poisoned<agnocast_shed>();
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_SHED, &shed), 0);
  EXPECT_EQ(shed.shed, 12u);  // 11 from the slow subscriber, entry 10 from the holder
  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/shed", &info, nullptr, &subs), 0);
  ASSERT_EQ(subs.size(), 2u);
  EXPECT_EQ(subs[0].unreceived, 1u);  // entry 11, still in the window
  EXPECT_EQ(subs[0].dropped, 11u);
  EXPECT_EQ(subs[1].held, 1u);
  // Every entry but the held one and the window's is reclaimable.
  EXPECT_EQ(shed.reclaimable, 10u);
  std::vector<uint64_t> addrs(64);
  auto rc = poisoned<agnocast_reclaim>();
  rc.reserved = 0;
  rc.reclaim = uptr(addrs.data());
  rc.reclaim_capacity = 64;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), 0);
  EXPECT_EQ(rc.reclaim_count, 10u);
  EXPECT_EQ(std::count(addrs.begin(), addrs.begin() + rc.reclaim_count, take.entry.addr), 0);
  // The held entry is intact and can still be released.
  EXPECT_EQ(release(dev, holder, take.entry.entry_id), 0);
  // Nothing more to shed; unregistered callers cannot.
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_SHED, &shed), 0);
  EXPECT_EQ(shed.shed, 0u);
  EXPECT_EQ(in_child([] {
              agnocast_shed s;
              return ioc(open_device(), AGNOCAST_IOC_SHED, &s) == -ESRCH ? 0 : 1;
            }),
            0);
}

// Past AGNOCAST_EXIT_RECORDS_MAX unread records, the oldest go, and the
// reader learns how many before anything else.
TEST_F(Trust, DiscardedExitRecordsAreReported) {
  // Earlier tests' children are torn down asynchronously: wait, then start empty.
  ASSERT_TRUE(eventually([&] { return list_processes(dev).empty(); }));
  drain_exit_records(dev);
  constexpr int kProcesses = 5, kSubscribers = 1000;
  for (int p = 0; p < kProcesses; p++) {
    ASSERT_EQ(in_child([&] {
                Registration r;
                int d = open_device();
                if (r.reserve(d)) return 10;
                Endpoint ep;
                for (int s = 0; s < kSubscribers; s++) {
                  if (add_subscriber(d, "/lost/" + std::to_string(p), 1, &ep)) return 11;
                }
                return 0;
              }),
              0);
  }
  // Read only once every record is queued, so exactly the oldest overflow.
  ASSERT_TRUE(eventually([&] { return list_processes(dev).empty(); }, 60000));
  const uint32_t total = kProcesses * (kSubscribers + 1);
  const uint32_t lost = total - AGNOCAST_EXIT_RECORDS_MAX;
  std::vector<agnocast_exit_record> records;
  ASSERT_TRUE(eventually(
      [&] {
        auto more = drain_exit_records(dev);
        records.insert(records.end(), more.begin(), more.end());
        return records.size() >= AGNOCAST_EXIT_RECORDS_MAX + 1;
      },
      60000));
  ASSERT_EQ(records.size(), AGNOCAST_EXIT_RECORDS_MAX + 1u);
  EXPECT_EQ(records[0].kind, static_cast<uint32_t>(AGNOCAST_EXIT_LOST));
  EXPECT_EQ(records[0].subscriber_id, lost);
  EXPECT_EQ(records.back().kind, static_cast<uint32_t>(AGNOCAST_EXIT_PROCESS));
  EXPECT_EQ(std::count_if(records.begin(), records.end(),
                          [](const auto& r) { return r.kind == AGNOCAST_EXIT_LOST; }),
            1);
}

uint32_t namespace_states() {
  struct stat st;
  if (stat("/sys/kernel/debug/agnocast", &st) != 0)
    mount("debugfs", "/sys/kernel/debug", "debugfs", 0, nullptr);
  std::ifstream in("/sys/kernel/debug/agnocast/namespaces");
  uint32_t n = 0;
  in >> n;
  return n;
}

// Namespace state ends with its namespace, even when a descriptor opened
// there outlives it, and a new namespace never sees an old one's.
TEST_F(Trust, NamespaceStateEndsWithItsNamespace) {
  const uint32_t before = namespace_states();
  ASSERT_GE(before, 1u);
  int sock[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_DGRAM, 0, sock), 0);
  std::vector<int> kept;
  for (int i = 0; i < 200; i++) {
    ASSERT_EQ(in_child([&] {
                if (unshare(CLONE_NEWIPC)) return 10;
                int d = open_device();
                agnocast_policy get{};
                if (ioc(d, AGNOCAST_IOC_GET_POLICY, &get) || get.flags) return 11;  // a fresh state
                // A policy stays while its namespace lives, with nothing open.
                if (set_policy(d, {}, true)) return 16;
                close(d);
                d = open_device();
                if (ioc(d, AGNOCAST_IOC_GET_POLICY, &get) || !(get.flags & AGNOCAST_POLICY_PRESENT))
                  return 17;
                agnocast_policy none{};
                if (ioc(d, AGNOCAST_IOC_SET_POLICY, &none)) return 18;
                Registration r;
                Endpoint ep;
                if (r.full(d) || add_subscriber(d, "/ns", 1, &ep)) return 12;
                if (set_policy(d, {}, true)) return 13;
                // Every tenth hands its descriptor out before its namespace dies.
                if (i % 10 == 0) {
                  char byte = 0;
                  struct iovec iov = {&byte, 1};
                  char control[CMSG_SPACE(sizeof(int))] = {};
                  struct msghdr msg = {};
                  msg.msg_iov = &iov;
                  msg.msg_iovlen = 1;
                  msg.msg_control = control;
                  msg.msg_controllen = sizeof(control);
                  struct cmsghdr* cmsg = CMSG_FIRSTHDR(&msg);
                  cmsg->cmsg_level = SOL_SOCKET;
                  cmsg->cmsg_type = SCM_RIGHTS;
                  cmsg->cmsg_len = CMSG_LEN(sizeof(int));
                  std::memcpy(CMSG_DATA(cmsg), &d, sizeof(int));
                  if (sendmsg(sock[1], &msg, 0) != 1) return 15;
                }
                return 0;  // dies registered: exit records stay in its namespace
              }),
              0)
        << "namespace " << i;
    if (i % 10 == 0) {
      char byte;
      char control[CMSG_SPACE(sizeof(int))];
      struct iovec iov = {&byte, 1};
      struct msghdr msg = {};
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = control;
      msg.msg_controllen = sizeof(control);
      ASSERT_EQ(recvmsg(sock[0], &msg, 0), 1);
      int fd;
      std::memcpy(&fd, CMSG_DATA(CMSG_FIRSTHDR(&msg)), sizeof(int));
      kept.push_back(fd);
    }
  }
  // A descriptor from a dead namespace acts on ours, which has no policy.
  agnocast_policy get{};
  ASSERT_EQ(ioc(kept[0], AGNOCAST_IOC_GET_POLICY, &get), 0);
  EXPECT_EQ(get.flags, 0u);
  // The descriptors kept the states of their (dead) namespaces alive.
  EXPECT_TRUE(eventually([&] {
    close(open_device());  // an open collects dead states
    return namespace_states() == before + kept.size();
  }));
  for (int fd : kept) close(fd);
  EXPECT_TRUE(eventually([&] {
    close(open_device());
    return namespace_states() == before;
  })) << namespace_states()
      << " states, " << before << " before";
  close(sock[0]);
  close(sock[1]);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
