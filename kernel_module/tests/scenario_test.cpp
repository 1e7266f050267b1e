// Multi-process behaviour: processes that publish, subscribe, fork, exec and
// die (kill -9 included), checked through introspection and exit records;
// read-only pool mappings; IPC-namespace isolation.
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "test_util.h"

using namespace agnocast_test;

namespace {

constexpr uint64_t kMagic = 0xC0DE000000000000ull;

// One-byte signal between parent and child.
struct Pipe {
  int fd[2];
  Pipe() { EXPECT_EQ(pipe(fd), 0); }
  ~Pipe() {
    close(fd[0]);
    close(fd[1]);
  }
  void notify() { EXPECT_EQ(write(fd[1], "x", 1), 1); }
  bool wait() {
    char c;
    return read(fd[0], &c, 1) == 1;
  }
};

class Scenario : public ::testing::Test {
 protected:
  void SetUp() override {
    dev = open_device();
    ASSERT_GE(dev, 0);
    ASSERT_EQ(reg.full(dev), 0);
    drain_exit_records(dev);
  }
  void TearDown() override {
    reg.drop();
    close(dev);
  }

  void kill_and_reap(pid_t pid) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    ASSERT_TRUE(eventually([&] { return !process_listed(dev, pid); }));
  }

  // Exit records of pid among those waiting now, in order.
  std::vector<agnocast_exit_record> records_of(pid_t pid) {
    std::vector<agnocast_exit_record> mine;
    for (const auto& r : drain_exit_records(dev))
      if (r.pid == pid) mine.push_back(r);
    return mine;
  }

  int dev = -1;
  Registration reg;
};

// Child body: a registered publisher that writes kMagic + entry id at each
// message and publishes until killed.
[[noreturn]] void publisher_forever(const char* topic, uint32_t depth, Pipe* ready,
                                    int after = 20) {
  int d = open_device();
  Registration r;
  Endpoint pub;
  if (r.full(d) || add_publisher(d, topic, depth, &pub)) _exit(10);
  for (uint64_t i = 0;; i++) {
    uint64_t off = (i % 4096) * 64;
    auto* slot = reinterpret_cast<volatile uint64_t*>(r.addr + off);
    *slot = kMagic + i;  // entry ids of a fresh topic with one publisher are 0, 1, 2...
    PublishResult res;
    if (publish(d, pub, r.addr + off, &res)) _exit(11);
    if (res.entry_id != i) _exit(12);
    if (i + 1 == static_cast<uint64_t>(after)) ready->notify();
    if (i > static_cast<uint64_t>(after)) usleep(1000);
  }
}

TEST_F(Scenario, PublisherKilledMidStreamLeavesEntriesReadable) {
  Endpoint sub;
  ASSERT_EQ(add_subscriber(dev, "/kill_pub", 4, &sub), 0);
  Pipe ready;
  pid_t child = fork();
  if (child == 0) publisher_forever("/kill_pub", 8, &ready);
  ASSERT_TRUE(ready.wait());

  // Hold two entries while the publisher still lives.
  ReceiveResult before;
  ASSERT_EQ(receive(dev, sub, &before, 2), 0);
  ASSERT_EQ(before.entries.size(), 2u);
  ASSERT_EQ(before.pools.size(), 1u);
  const agnocast_pool pool = before.pools[0];
  EXPECT_EQ(pool.pid, child);
  EXPECT_GE(pool.fd, 0);
  EXPECT_EQ(fcntl(pool.fd, F_GETFD) & FD_CLOEXEC, FD_CLOEXEC);

  kill_and_reap(child);

  agnocast_topic_info info;
  std::vector<agnocast_publisher_info> pubs;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/kill_pub", &info, &pubs, &subs), 0);
  EXPECT_EQ(info.publisher_total, 0u);
  ASSERT_EQ(info.subscriber_total, 1u);
  EXPECT_EQ(subs[0].held, 2u);
  // Only subscriber references keep entries now: the window went with it.
  EXPECT_EQ(info.entries, subs[0].held + subs[0].unreceived);

  ReceiveResult after;
  ASSERT_EQ(receive(dev, sub, &after), 0);
  EXPECT_EQ(after.entries.size(), subs[0].unreceived);
  EXPECT_TRUE(after.pools.empty());  // a pool is handed over once

  // The dead publisher's memory is still there, read-only, at its address.
  void* map = mmap(reinterpret_cast<void*>(pool.addr), pool.size, PROT_READ,
                   MAP_SHARED | MAP_FIXED_NOREPLACE, pool.fd, 0);
  ASSERT_NE(map, MAP_FAILED) << strerror(errno);
  for (const auto* list : {&before.entries, &after.entries}) {
    for (const auto& e : *list) {
      EXPECT_EQ(*reinterpret_cast<const uint64_t*>(e.addr), kMagic + e.entry_id);
      EXPECT_EQ(release(dev, sub, e.entry_id), 0);
    }
  }
  ASSERT_EQ(topic_info(dev, "/kill_pub", &info), 0);
  EXPECT_EQ(info.entries, 0u);
  munmap(map, pool.size);
  close(pool.fd);

  auto recs = records_of(child);
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_EQ(recs[0].kind, static_cast<uint32_t>(AGNOCAST_EXIT_PROCESS));
  // Owner gone and no entry left: the pool is freed, and no longer counted.
  for (const auto& p : list_processes(dev))
    if (p.pid == getpid()) {
      EXPECT_EQ(p.pools_mapped, 0u);
    }
}

// A dead publisher's slot is free again once its entries are released, even
// though a live subscriber still maps its pool; that subscriber is handed the
// next pool of the slot before it reads an entry there.
TEST_F(Scenario, DeadPublishersSlotIsReusedWhileSubscriberLives) {
  auto mapped_by_us = [&] {
    for (const auto& p : list_processes(dev))
      if (p.pid == getpid()) return p.pools_mapped;
    return ~0u;
  };
  void* view = nullptr;
  uint64_t slot_addr = 0, slot_size = 0;
  for (int generation = 0; generation < 2; generation++) {
    // A fresh topic each time: publisher_forever expects entry ids from 0.
    const std::string topic = "/slot_reuse_" + std::to_string(generation);
    Endpoint sub;
    ASSERT_EQ(add_subscriber(dev, topic.c_str(), 4, &sub), 0);
    Pipe ready;
    pid_t child = fork();
    if (child == 0) {
      // As the library's fork handler does: the parent's pool views are not ours.
      if (view) munmap(view, slot_size);
      publisher_forever(topic.c_str(), 1, &ready, 1);
    }
    ASSERT_TRUE(ready.wait());
    ReceiveResult rr;
    ASSERT_EQ(receive(dev, sub, &rr, 1), 0);
    ASSERT_EQ(rr.entries.size(), 1u);
    // Each generation's pool is handed over, the second one at the same slot.
    ASSERT_EQ(rr.pools.size(), 1u) << "generation " << generation;
    const agnocast_pool pool = rr.pools[0];
    EXPECT_EQ(pool.pid, child);
    if (generation == 0) {
      slot_addr = pool.addr;
      slot_size = pool.size;
    }
    EXPECT_EQ(pool.addr, slot_addr);
    // The second mapping replaces the stale view of the first pool.
    view = mmap(reinterpret_cast<void*>(pool.addr), pool.size, PROT_READ,
                MAP_SHARED | (view ? MAP_FIXED : MAP_FIXED_NOREPLACE), pool.fd, 0);
    ASSERT_EQ(view, reinterpret_cast<void*>(pool.addr)) << strerror(errno);
    close(pool.fd);
    const auto& entry = rr.entries[0];
    EXPECT_EQ(*reinterpret_cast<const uint64_t*>(entry.addr), kMagic + entry.entry_id);
    EXPECT_EQ(mapped_by_us(), 1u);

    EXPECT_EQ(release(dev, sub, entry.entry_id), 0);
    kill_and_reap(child);
    // Nothing of the dead publisher is left unreceived or held.
    ReceiveResult rest;
    ASSERT_EQ(receive(dev, sub, &rest), 0);
    for (const auto& e : rest.entries) EXPECT_EQ(release(dev, sub, e.entry_id), 0);
    for (const auto& p : rest.pools) close(p.fd);
    ASSERT_TRUE(eventually([&] { return mapped_by_us() == 0; }));
  }
  munmap(view, slot_size);
}

// TAKE, as a ReceiveResult of at most one entry and one pool.
int take(int dev, Endpoint sub, ReceiveResult* res) {
  agnocast_take arg{};
  arg.topic_handle = sub.handle;
  arg.subscriber_id = sub.id;
  int ret = ioc(dev, AGNOCAST_IOC_TAKE, &arg);
  if (!ret) {
    res->entries.assign(&arg.entry, &arg.entry + arg.entry_count);
    res->pools.assign(&arg.pool, &arg.pool + arg.pool_count);
  }
  return ret;
}

// RECEIVE and TAKE install a pool's descriptor with no lock held. An entry
// that goes meanwhile (dropped for a newer one from a pool the caller has)
// must take its pool out of the answer: a dead pool's file mapped at its
// address would hide the pool that gets its slot next. A thread publishes
// into the depth-1 subscription after a delay swept across attempts, so that
// some drops land while the dead child's pool is being installed. The call
// starts once the dropper counts the delay, so that a dropper scheduled late
// (a loaded host) still drops within the sweep.
void race_drop_against_install(int dev, const Registration& reg, bool polling) {
  // Both outcomes (the child's entry received, or dropped first) must occur
  // for the race to have been run at all. A round of kAttempts that lacks
  // one is followed by another, with the delays four times as long (up to
  // 256 times) if no child's entry was received, until both have occurred or
  // kOvertime has passed.
  constexpr int kAttempts = 150;
  constexpr auto kOvertime = std::chrono::seconds(60);
  const std::string topic = polling ? "/stray_grant_take" : "/stray_grant_receive";
  Endpoint sub, own;
  ASSERT_EQ(add_subscriber(dev, topic, 1, &sub, polling ? AGNOCAST_POLLING : 0), 0);
  ASSERT_EQ(add_publisher(dev, topic, 1, &own), 0);
  auto answer = [&](ReceiveResult* rr) {
    return polling ? take(dev, sub, rr) : receive(dev, sub, rr, 1);
  };

  // The delay (in spins) before the next drop; kIdle between attempts,
  // kCounting while the dropper counts it.
  constexpr int kIdle = -1, kEnd = -2, kCounting = -3;
  std::atomic<int> drop_after{kIdle};
  std::atomic<int> drop_failures{0};
  std::thread dropper([&] {
    for (uint64_t i = 0;; i++) {
      int spins;
      while ((spins = drop_after.load()) == kIdle) sched_yield();
      if (spins == kEnd) return;
      drop_after.store(kCounting);
      for (int s = 0; s < spins; s++) __asm__ volatile("");
      if (publish(dev, own, reg.addr + (i % 4096) * 64)) drop_failures++;
      drop_after.store(kIdle);
    }
  });
  struct StopDropper {
    std::atomic<int>& drop_after;
    std::thread& dropper;
    ~StopDropper() {
      while (drop_after.load() != kIdle) sched_yield();
      drop_after.store(kEnd);
      dropper.join();
    }
  } stop_dropper{drop_after, dropper};

  int attempt = 0, received_child = 0, pools_handed = 0;
  auto check = [&](const ReceiveResult& rr) {
    for (const auto& pool : rr.pools) {
      const bool holds = std::any_of(rr.entries.begin(), rr.entries.end(), [&](const auto& e) {
        return e.addr >= pool.addr && e.addr < pool.addr + pool.size;
      });
      EXPECT_TRUE(holds) << "attempt " << attempt << ": the pool of pid " << pool.pid
                         << " was handed over with none of the call's entries in it";
      pools_handed++;
      close(pool.fd);
    }
    for (const auto& e : rr.entries) {
      if (e.addr < reg.addr || e.addr >= reg.addr + reg.size) received_child++;
      EXPECT_EQ(release(dev, sub, e.entry_id), 0);
    }
  };
  const auto overtime_end = std::chrono::steady_clock::now() + kOvertime;
  int delay_scale = 1;
  for (; !::testing::Test::HasFailure(); attempt++) {
    if (attempt && attempt % kAttempts == 0) {
      if ((received_child > 0 && received_child < attempt) ||
          std::chrono::steady_clock::now() > overtime_end)
        break;
      if (!received_child) delay_scale = std::min(delay_scale * 4, 256);
    }
    Pipe ready;
    pid_t child = fork();
    if (child == 0) {
      // Publishes one entry and dies: its pool lives as long as the entry.
      int d = open_device();
      Registration r;
      Endpoint pub;
      if (r.full(d) || add_publisher(d, topic, 1, &pub)) _exit(10);
      *reinterpret_cast<volatile uint64_t*>(r.addr) = kMagic;
      if (publish(d, pub, r.addr)) _exit(11);
      ready.notify();
      _exit(0);
    }
    ASSERT_TRUE(ready.wait());
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;

    drop_after.store((attempt * 37) % 4000 * delay_scale);
    while (drop_after.load() >= 0) sched_yield();
    ReceiveResult rr;
    ASSERT_EQ(answer(&rr), 0);
    while (drop_after.load() != kIdle) sched_yield();
    check(rr);
    ReceiveResult rest;
    ASSERT_EQ(answer(&rest), 0);
    check(rest);
  }
  EXPECT_EQ(drop_failures.load(), 0);
  std::printf("%d of %d children's entries received, %d pools handed over (delays x%d)\n",
              received_child, attempt, pools_handed, delay_scale);
  EXPECT_GT(received_child, 0);
  EXPECT_LT(received_child, attempt);
}

TEST_F(Scenario, ReceiveHandsOverOnlyThePoolsOfItsEntries) {
  race_drop_against_install(dev, reg, false);
}

TEST_F(Scenario, TakeHandsOverOnlyThePoolOfItsEntry) { race_drop_against_install(dev, reg, true); }

TEST_F(Scenario, SubscriberKilledMidStreamReleasesEverything) {
  Endpoint pub;
  ASSERT_EQ(add_publisher(dev, "/kill_sub", 2, &pub), 0);
  Pipe ready;
  pid_t child = fork();
  if (child == 0) {
    int d = open_device();
    Registration r;
    Endpoint cb, poll;
    if (r.full(d) || add_subscriber(d, "/kill_sub", 8, &cb) ||
        add_subscriber(d, "/kill_sub", 8, &poll, AGNOCAST_POLLING))
      _exit(10);
    ready.notify();
    for (;;) {
      ReceiveResult rr;
      if (receive(d, cb, &rr, 3)) _exit(11);  // holds everything it receives
      usleep(1000);
    }
  }
  ASSERT_TRUE(ready.wait());
  PublishResult res;
  std::vector<uint64_t> reclaimed;
  uint64_t published = 0;
  for (int i = 0; i < 50; i++, published++) {
    ASSERT_EQ(publish(dev, pub, reg.addr + 64 * i, &res), 0);
    EXPECT_EQ(res.wake.size(), 1u);
    reclaimed.insert(reclaimed.end(), res.reclaim.begin(), res.reclaim.end());
    usleep(500);
  }
  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/kill_sub", &info, nullptr, &subs), 0);
  ASSERT_EQ(subs.size(), 2u);
  const uint32_t cb_id = subs[0].id;
  EXPECT_GT(subs[0].held, 0u);

  kill_and_reap(child);
  ASSERT_EQ(topic_info(dev, "/kill_sub", &info, nullptr, &subs), 0);
  EXPECT_EQ(info.subscriber_total, 0u);
  EXPECT_EQ(info.entries, 2u);  // just the publisher's window

  // Everything but the window comes back for reclaim, each address once.
  for (;;) {
    uint64_t addrs[64];
    agnocast_reclaim rc{uptr(addrs), 64, 0, 0, 0};
    ASSERT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), 0);
    reclaimed.insert(reclaimed.end(), addrs, addrs + rc.reclaim_count);
    if (!rc.reclaim_pending) break;
  }
  EXPECT_EQ(reclaimed.size(), published - 2);
  std::sort(reclaimed.begin(), reclaimed.end());
  EXPECT_EQ(std::unique(reclaimed.begin(), reclaimed.end()), reclaimed.end());

  ASSERT_EQ(publish(dev, pub, reg.addr, &res), 0);
  EXPECT_TRUE(res.wake.empty());

  auto recs = records_of(child);
  ASSERT_EQ(recs.size(), 2u);  // the polling subscriber owns no queue
  EXPECT_EQ(recs[0].kind, static_cast<uint32_t>(AGNOCAST_EXIT_QUEUE));
  EXPECT_STREQ(recs[0].topic, "/kill_sub");
  EXPECT_EQ(recs[0].subscriber_id, cb_id);
  EXPECT_EQ(recs[1].kind, static_cast<uint32_t>(AGNOCAST_EXIT_PROCESS));
}

TEST_F(Scenario, ManyThreadsKilledTogether) {
  Pipe ready;
  pid_t child = fork();
  if (child == 0) {
    int d = open_device();
    Registration r;
    Endpoint sub;
    if (r.full(d) || add_subscriber(d, "/threads", 1, &sub)) _exit(10);
    std::vector<pthread_t> threads(6);
    for (auto& t : threads)
      pthread_create(
          &t, nullptr,
          [](void* p) -> void* {
            int fd = *static_cast<int*>(p);
            for (;;) {
              agnocast_list_topics l{0, 0, 0, 0, 0};
              ioctl(fd, AGNOCAST_IOC_LIST_TOPICS, &l);
            }
          },
          &d);
    ready.notify();
    pause();
  }
  ASSERT_TRUE(ready.wait());
  EXPECT_TRUE(process_listed(dev, child));
  kill_and_reap(child);
  agnocast_topic_info info;
  EXPECT_EQ(topic_info(dev, "/threads", &info), -ENOENT);
  auto recs = records_of(child);
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_EQ(recs[1].kind, static_cast<uint32_t>(AGNOCAST_EXIT_PROCESS));
}

TEST_F(Scenario, ForkedChildIsNotRegisteredAndDiesAlone) {
  Endpoint pub;
  ASSERT_EQ(add_publisher(dev, "/fork", 1, &pub), 0);
  // The child inherits the descriptor but not the registration.
  EXPECT_EQ(in_child([&] {
              Endpoint ep;
              if (add_publisher(dev, "/fork", 1, &ep) != -ESRCH) return 10;
              if (publish(dev, pub, reg.addr) != -ESRCH) return 11;
              Registration r;
              if (r.reserve(dev)) return 12;
              if (r.addr == reg.addr) return 13;
              return 0;
            }),
            0);
  ASSERT_TRUE(eventually([&] { return list_processes(dev).size() == 1; }));
  EXPECT_TRUE(process_listed(dev, getpid()));
  EXPECT_EQ(publish(dev, pub, reg.addr), 0);

  // A registered parent killed after forking a registered child: only the
  // parent goes.
  Pipe ready;
  pid_t parent = fork();
  if (parent == 0) {
    Registration r;
    if (r.reserve(dev)) _exit(10);
    pid_t grandchild = fork();
    if (grandchild == 0) {
      Registration g;
      if (g.reserve(dev)) _exit(10);
      ready.notify();
      pause();
    }
    pause();
  }
  ASSERT_TRUE(ready.wait());
  auto procs = list_processes(dev);
  ASSERT_EQ(procs.size(), 3u);
  pid_t grandchild = 0;
  for (const auto& p : procs)
    if (p.pid != getpid() && p.pid != parent) grandchild = p.pid;
  ASSERT_NE(grandchild, 0);
  kill_and_reap(parent);
  EXPECT_TRUE(process_listed(dev, grandchild));
  kill(grandchild, SIGKILL);
  ASSERT_TRUE(eventually([&] { return !process_listed(dev, grandchild); }));
}

TEST_F(Scenario, ExecDropsTheOldRegistration) {
  pid_t child = fork();
  if (child == 0) {
    int d = open_device(O_RDWR);
    int inherited = fcntl(d, F_DUPFD, 100);  // without O_CLOEXEC
    Registration r;
    Endpoint sub;
    if (r.full(d) || add_subscriber(d, "/exec", 1, &sub)) _exit(10);
    std::string fd = std::to_string(inherited);
    execl("/proc/self/exe", "scenario", "--exec-child", fd.c_str(), nullptr);
    _exit(11);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  ASSERT_TRUE(eventually([&] { return !process_listed(dev, child); }));
  auto recs = records_of(child);
  // Exec and then exit: each time the subscriber's queue and the process.
  ASSERT_EQ(recs.size(), 4u);
  for (int i : {0, 2}) {
    EXPECT_EQ(recs[i].kind, static_cast<uint32_t>(AGNOCAST_EXIT_QUEUE));
    EXPECT_STREQ(recs[i].topic, "/exec");
    EXPECT_EQ(recs[i + 1].kind, static_cast<uint32_t>(AGNOCAST_EXIT_PROCESS));
  }
  EXPECT_EQ(recs[0].subscriber_id, 0u);
  EXPECT_EQ(recs[2].subscriber_id, 1u);
}

// exec is detected when it happens: the new program makes no agnocast call,
// yet the old registration is gone (and its exit records queued) while it runs.
TEST_F(Scenario, ExecIsDetectedAtExec) {
  Pipe registered;
  pid_t child = fork();
  if (child == 0) {
    int d = open_device(O_RDWR);
    Registration r;
    Endpoint sub;
    if (r.full(d) || add_subscriber(d, "/exec_now", 1, &sub)) _exit(10);
    registered.notify();
    execl("/proc/self/exe", "scenario", "--pause-child", nullptr);
    _exit(11);
  }
  ASSERT_TRUE(registered.wait());
  agnocast_topic_info info;
  ASSERT_TRUE(eventually([&] { return topic_info(dev, "/exec_now", &info) == -ENOENT; }));
  EXPECT_FALSE(process_listed(dev, child));
  EXPECT_EQ(waitpid(child, nullptr, WNOHANG), 0);  // still running the new program
  auto recs = records_of(child);
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_EQ(recs[0].kind, static_cast<uint32_t>(AGNOCAST_EXIT_QUEUE));
  EXPECT_STREQ(recs[0].topic, "/exec_now");
  EXPECT_EQ(recs[1].kind, static_cast<uint32_t>(AGNOCAST_EXIT_PROCESS));
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  EXPECT_TRUE(records_of(child).empty());  // no registration left to report
}

// After exec: the inherited descriptor still works, but the registration is
// gone; registering again succeeds.
int exec_child(int fd) {
  Endpoint ep;
  if (add_publisher(fd, "/exec", 1, &ep) != -ESRCH) return 20;
  agnocast_topic_info info;
  if (topic_info(fd, "/exec", &info) != -ENOENT) return 21;
  Registration r;
  if (r.reserve(fd)) return 22;
  if (add_subscriber(fd, "/exec", 1, &ep)) return 23;
  return 0;
}

TEST_F(Scenario, ReceivedPoolIsReadOnly) {
  Endpoint sub;
  ASSERT_EQ(add_subscriber(dev, "/ro", 4, &sub), 0);
  Pipe ready;
  pid_t child = fork();
  if (child == 0) publisher_forever("/ro", 8, &ready, 1);
  ASSERT_TRUE(ready.wait());
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr, 1), 0);
  ASSERT_EQ(rr.pools.size(), 1u);
  const agnocast_pool pool = rr.pools[0];

  // The descriptor is read-only: no writable shared mapping, no upgrade.
  EXPECT_EQ(fcntl(pool.fd, F_GETFL) & O_ACCMODE, O_RDONLY);
  void* w = mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, pool.fd, 0);
  EXPECT_EQ(w, MAP_FAILED);
  EXPECT_EQ(errno, EACCES);
  void* map = mmap(reinterpret_cast<void*>(pool.addr), pool.size, PROT_READ,
                   MAP_SHARED | MAP_FIXED_NOREPLACE, pool.fd, 0);
  ASSERT_EQ(map, reinterpret_cast<void*>(pool.addr)) << strerror(errno);
  EXPECT_EQ(mprotect(map, 4096, PROT_READ | PROT_WRITE), -1);
  EXPECT_EQ(errno, EACCES);
  const uint64_t addr = rr.entries[0].addr;
  EXPECT_EQ(*reinterpret_cast<const uint64_t*>(addr), kMagic + rr.entries[0].entry_id);

  // A write faults.
  EXPECT_EQ(in_child([&] {
              *reinterpret_cast<volatile uint64_t*>(addr) = 1;
              return 0;
            }),
            128 + SIGSEGV);
  EXPECT_EQ(*reinterpret_cast<const uint64_t*>(addr), kMagic + rr.entries[0].entry_id);
  kill_and_reap(child);
  EXPECT_EQ(*reinterpret_cast<const uint64_t*>(addr), kMagic + rr.entries[0].entry_id);
  munmap(map, pool.size);
  close(pool.fd);
}

TEST(Namespace, IpcNamespacesAreIsolated) {
  int dev = open_device();
  ASSERT_GE(dev, 0);
  Registration reg;
  ASSERT_EQ(reg.full(dev), 0);
  Endpoint pub;
  ASSERT_EQ(add_publisher(dev, "/ns/topic", 1, &pub), 0);
  ASSERT_EQ(add_publisher(dev, "/ns/topic", 1, &pub), 0);
  ASSERT_EQ(pub.id, 1u);

  EXPECT_EQ(in_child([&] {
              if (unshare(CLONE_NEWIPC)) return 10;
              int d = open_device();
              agnocast_list_topics l{0, 0, 0xA5A5A5A5u, 0, 0};
              if (ioc(d, AGNOCAST_IOC_LIST_TOPICS, &l) || l.total != 0) return 11;
              agnocast_topic_info info;
              if (topic_info(d, "/ns/topic", &info) != -ENOENT) return 12;
              if (!list_processes(d).empty()) return 13;
              munmap(reg.map, reg.size);  // inherited from the parent's slot 0
              Registration r;
              if (r.full(d)) return 14;
              // A fresh namespace: its own slots and its own ids.
              if (r.addr != module_pool_base()) return 15;
              Endpoint ep;
              if (add_publisher(d, "/ns/topic", 1, &ep) || ep.id != 0) return 16;
              if (list_processes(d).size() != 1) return 17;
              return 0;
            }),
            0);
  agnocast_topic_info info;
  ASSERT_EQ(topic_info(dev, "/ns/topic", &info), 0);
  EXPECT_EQ(info.publisher_total, 2u);
  // The child's exit record went to its own namespace.
  EXPECT_TRUE(eventually([&] { return list_processes(dev).size() == 1; }));
  for (const auto& r : drain_exit_records(dev)) EXPECT_NE(r.kind, 0u);
  reg.drop();
  close(dev);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--exec-child") return exec_child(std::atoi(argv[2]));
  if (argc == 2 && std::string(argv[1]) == "--pause-child") {
    pause();  // a new program that never touches agnocast
    return 0;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
