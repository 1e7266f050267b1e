// Many processes on many topics at once: publish, receive with batched
// releases, take, release lists and shed on 32 topics from 8 processes, some
// of them killed mid-way and replaced.  Every call must succeed or fail only
// as the UAPI allows; afterwards nothing is left behind.  The VM suite checks
// the kernel log (lockdep, KASAN, warnings) after it.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string>

#include "test_util.h"

using namespace agnocast_test;

namespace {

constexpr int kTopics = 32;
constexpr int kWorkers = 8;
constexpr int kPublishersPerWorker = kTopics / kWorkers;
constexpr int kSubscriptionsPerWorker = 8;

std::string topic_name(int t) { return "/stress/t" + std::to_string(t); }

struct Subscription {
  Endpoint ep;
  bool polling = false;
  std::vector<uint64_t> held;
};

// Worker body; returns 0 or the number of the check that failed.
int worker(int index, std::chrono::steady_clock::time_point until) {
  int d = open_device();
  Registration reg;
  if (reg.full(d)) return 10;
  std::vector<Endpoint> pubs;
  for (int k = 0; k < kPublishersPerWorker; k++) {
    Endpoint ep;
    if (add_publisher(d, topic_name(index * kPublishersPerWorker + k), 4, &ep)) return 11;
    pubs.push_back(ep);
  }
  std::vector<Subscription> subs;
  for (int k = 1; k <= kSubscriptionsPerWorker; k++) {
    Subscription s;
    s.polling = k % 3 == 0;
    int t = (index * kPublishersPerWorker + 3 * k) % kTopics;
    if (add_subscriber(d, topic_name(t), 1 + k % 4, &s.ep, s.polling ? AGNOCAST_POLLING : 0))
      return 12;
    subs.push_back(s);
  }

  std::vector<agnocast_entry> entries(8);
  std::vector<agnocast_pool> pools(AGNOCAST_RECEIVE_POOLS_MAX);
  uint64_t n = 0;
  while (std::chrono::steady_clock::now() < until) {
    for (const Endpoint& p : pubs) {
      PublishResult res;
      if (publish(d, p, reg.addr + 64 * (n++ % 4096), &res, 16)) return 20;
    }
    for (Subscription& s : subs) {
      if (s.polling) {
        auto take = poisoned_request<agnocast_take>();
        take.topic_handle = s.ep.handle;
        take.subscriber_id = s.ep.id;
        if (ioc(d, AGNOCAST_IOC_TAKE, &take)) return 21;
        if (take.pool_count) close(take.pool.fd);
        if (take.entry_count) s.held.push_back(take.entry.entry_id);
        if (s.held.size() >= 3) {
          if (release_list(d, s.ep, s.held)) return 22;
          s.held.clear();
        }
        continue;
      }
      agnocast_receive arg{};
      arg.topic_handle = s.ep.handle;
      arg.subscriber_id = s.ep.id;
      arg.entries = uptr(entries.data());
      arg.pools = uptr(pools.data());
      arg.entry_capacity = static_cast<uint32_t>(entries.size());
      arg.pool_capacity = static_cast<uint32_t>(pools.size());
      arg.release_ids = uptr(s.held.data());
      arg.release_count = static_cast<uint32_t>(s.held.size());
      if (ioc(d, AGNOCAST_IOC_RECEIVE, &arg)) return 23;
      for (uint32_t i = 0; i < arg.pool_count; i++) close(pools[i].fd);
      s.held.clear();
      for (uint32_t i = 0; i < arg.entry_count; i++) s.held.push_back(entries[i].entry_id);
    }
    if (n % 64 == 0) {
      agnocast_shed shed{};
      if (ioc(d, AGNOCAST_IOC_SHED, &shed)) return 24;
    }
  }
  // A worker that barely ran proves nothing.
  return n >= 8 * kPublishersPerWorker ? 0 : 30;
}

TEST(Stress, ManyTopicsFromManyProcesses) {
  int dev = open_device();
  ASSERT_GE(dev, 0);
  const auto duration = std::chrono::seconds(std::getenv("AGNOCAST_STRESS_SECONDS")
                                                 ? std::atoi(std::getenv("AGNOCAST_STRESS_SECONDS"))
                                                 : 8);
  const auto start = std::chrono::steady_clock::now();
  auto spawn = [&](int index) {
    pid_t pid = fork();
    if (pid == 0) _exit(worker(index, start + duration));
    return pid;
  };
  std::vector<pid_t> workers;
  for (int i = 0; i < kWorkers; i++) workers.push_back(spawn(i));

  // Half-way, two workers die by SIGKILL in the middle of whatever call they
  // are in, and replacements take their topics over.
  std::this_thread::sleep_for(duration / 2);
  for (int victim : {1, 5}) {
    kill(workers[victim], SIGKILL);
    int status = 0;
    ASSERT_EQ(waitpid(workers[victim], &status, 0), workers[victim]);
    EXPECT_TRUE(WIFSIGNALED(status));
    workers[victim] = spawn(victim);
  }
  for (pid_t pid : workers) {
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
        << "worker " << pid << " status " << status;
  }

  // Nothing is left: no process, no topic.
  EXPECT_TRUE(eventually([&] { return list_processes(dev).empty(); }));
  agnocast_list_topics lt{0, 0, 0, 0, 0};
  EXPECT_TRUE(eventually([&] { return !ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt) && !lt.total; }));
  drain_exit_records(dev);
  close(dev);
}

}  // namespace
