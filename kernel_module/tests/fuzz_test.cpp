// Randomized ioctl fuzzer: several processes, two threads each, issue random
// commands with random, garbage or bad-pointer arguments for a bounded time;
// the parent kills and respawns workers at random.  Afterwards every process
// must be torn down and every topic gone.  The VM bed checks the kernel log.
//
// usage: agnocast_fuzz_test [SECONDS] [PROCESSES]
#include <poll.h>
#include <pthread.h>
#include <sys/syscall.h>

#include <atomic>
#include <cstdio>
#include <random>

#include "test_util.h"

using namespace agnocast_test;

namespace {

const unsigned long kCommands[] = {
    AGNOCAST_IOC_GET_VERSION,
    AGNOCAST_IOC_REGISTER_PROCESS,
    AGNOCAST_IOC_UNREGISTER_PROCESS,
    AGNOCAST_IOC_ADD_PUBLISHER,
    AGNOCAST_IOC_REMOVE_PUBLISHER,
    AGNOCAST_IOC_ADD_SUBSCRIBER,
    AGNOCAST_IOC_REMOVE_SUBSCRIBER,
    AGNOCAST_IOC_PUBLISH,
    AGNOCAST_IOC_RECLAIM,
    AGNOCAST_IOC_RECEIVE,
    AGNOCAST_IOC_TAKE,
    AGNOCAST_IOC_RELEASE,
    AGNOCAST_IOC_LIST_TOPICS,
    AGNOCAST_IOC_TOPIC_INFO,
    AGNOCAST_IOC_LIST_PROCESSES,
};
const char* const kTopics[] = {"/a", "/a/b", "/a_b", "/chatter", "/x/y/z", "/x_y/z", "/q"};

// A page of scratch memory followed by an inaccessible page, so that
// arguments can straddle into a fault.
struct Arena {
  uint8_t* base;
  Arena() {
    base = static_cast<uint8_t*>(
        mmap(nullptr, 3 * 4096, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    mprotect(base + 2 * 4096, 4096, PROT_NONE);
  }
};

struct Worker {
  std::mt19937_64 rng;
  int dev;
  Registration* reg;
  bool owns_registration;
  Arena arena;
  std::vector<Endpoint> pubs, subs;
  std::vector<uint64_t> entries;

  uint64_t rnd(uint64_t n) { return n ? rng() % n : 0; }
  bool chance(int percent) { return rnd(100) < static_cast<uint64_t>(percent); }

  void* bad_pointer() {
    switch (rnd(5)) {
      case 0:
        return nullptr;
      case 1:
        return reinterpret_cast<void*>(1 + rnd(4095));
      case 2:
        return reinterpret_cast<void*>(0xffffffff81000000ull + rnd(1 << 20));
      case 3:
        return arena.base + 2 * 4096 - rnd(64);  // straddles the guard page
      default:
        return reinterpret_cast<void*>(0x7ffffffff000ull - rnd(1 << 20) * 8);
    }
  }

  uint64_t some_ptr(size_t bytes) {
    if (chance(10)) return uptr(bad_pointer());
    return uptr(arena.base + 4096 - std::min<size_t>(bytes, 4096) / 2 * rnd(2));
  }

  uint32_t some_u32(uint32_t typical) {
    switch (rnd(6)) {
      case 0:
        return static_cast<uint32_t>(rng());
      case 1:
        return 0;
      case 2:
        return 0xffffffffu;
      default:
        return static_cast<uint32_t>(rnd(typical + 1));
    }
  }

  Endpoint some_endpoint(const std::vector<Endpoint>& v) {
    if (v.empty() || chance(15)) return {some_u32(8), some_u32(8)};
    return v[rnd(v.size())];
  }

  void garbage() {
    unsigned long cmd = kCommands[rnd(std::size(kCommands))];
    if (chance(10)) cmd = static_cast<unsigned long>(rng());
    if (chance(10)) cmd ^= 1ul << rnd(32);
    void* arg;
    if (chance(40)) {
      arg = bad_pointer();
    } else {
      for (int i = 0; i < 4096; i += 8) *reinterpret_cast<uint64_t*>(arena.base + i) = rng();
      arg = arena.base + rnd(512);
    }
    ioctl(dev, cmd, arg);
  }

  void add_endpoint(bool publisher) {
    auto ep = endpoint(kTopics[rnd(std::size(kTopics))], 1 + rnd(chance(5) ? 1100 : 8),
                       static_cast<uint32_t>(rnd(chance(5) ? 16 : 4)));
    if (chance(5)) ep.node[rnd(sizeof(ep.node))] = static_cast<char>(rng());
    if (ioc(dev, publisher ? AGNOCAST_IOC_ADD_PUBLISHER : AGNOCAST_IOC_ADD_SUBSCRIBER, &ep)) return;
    (publisher ? pubs : subs).push_back({ep.topic_handle, ep.id});
  }

  void remove_endpoint(bool publisher) {
    auto& v = publisher ? pubs : subs;
    Endpoint e = some_endpoint(v);
    agnocast_remove_endpoint rm{e.handle, e.id};
    if (ioc(dev, publisher ? AGNOCAST_IOC_REMOVE_PUBLISHER : AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm) ==
        0)
      std::erase_if(v, [&](const Endpoint& x) { return x.handle == e.handle && x.id == e.id; });
  }

  void do_publish() {
    Endpoint e = some_endpoint(pubs);
    agnocast_publish arg{};
    arg.topic_handle = e.handle;
    arg.publisher_id = e.id;
    arg.addr = reg->addr + (chance(90) ? rnd(reg->size ? reg->size : 1) : rng());
    arg.bytes = rng();
    arg.wake_ids = some_ptr(4096);
    arg.wake_capacity = chance(80) ? 1024 : some_u32(4);
    arg.reclaim = some_ptr(4096);
    arg.reclaim_capacity = static_cast<uint32_t>(rnd(512));
    arg.reserved = chance(3) ? 1 : 0;
    ioctl(dev, AGNOCAST_IOC_PUBLISH, &arg);
  }

  void close_pools(const agnocast_pool* pools, uint32_t n) {
    for (uint32_t i = 0; i < n; i++) {
      if (chance(20)) {
        void* m = mmap(reinterpret_cast<void*>(pools[i].addr), 4096, PROT_READ,
                       MAP_SHARED | MAP_FIXED_NOREPLACE, pools[i].fd, 0);
        if (m != MAP_FAILED) munmap(m, 4096);
      }
      close(pools[i].fd);
    }
  }

  void do_receive() {
    Endpoint e = some_endpoint(subs);
    agnocast_entry ents[16];
    agnocast_pool pools[4];
    agnocast_receive arg{};
    arg.topic_handle = e.handle;
    arg.subscriber_id = e.id;
    arg.entries = chance(90) ? uptr(ents) : uptr(bad_pointer());
    arg.pools = chance(90) ? uptr(pools) : uptr(bad_pointer());
    arg.entry_capacity = static_cast<uint32_t>(rnd(17));
    arg.pool_capacity = static_cast<uint32_t>(rnd(5));
    // Releases batched into the receive: held ids, unknown ones, a bad list.
    uint64_t release_ids[2];
    arg.release_count = static_cast<uint32_t>(rnd(3));
    for (uint32_t i = 0; i < arg.release_count; i++)
      release_ids[i] = entries.empty() || chance(20) ? rnd(64) : entries[rnd(entries.size())];
    arg.release_ids = chance(95) ? uptr(release_ids) : uptr(bad_pointer());
    if (ioc(dev, AGNOCAST_IOC_RECEIVE, &arg)) return;
    for (uint32_t i = 0; i < arg.entry_count; i++) entries.push_back(ents[i].entry_id);
    close_pools(pools, arg.pool_count);
  }

  void do_take() {
    Endpoint e = some_endpoint(subs);
    agnocast_take arg{};
    arg.topic_handle = e.handle;
    arg.subscriber_id = e.id;
    if (ioc(dev, AGNOCAST_IOC_TAKE, &arg)) return;
    if (arg.entry_count) entries.push_back(arg.entry.entry_id);
    close_pools(&arg.pool, arg.pool_count);
  }

  void do_release() {
    Endpoint e = some_endpoint(subs);
    uint64_t ids[3];
    uint32_t count = 1 + static_cast<uint32_t>(rnd(3));
    for (uint32_t i = 0; i < count; i++)
      ids[i] = entries.empty() || chance(20) ? rnd(64) : entries[rnd(entries.size())];
    agnocast_release arg{e.handle, e.id, chance(95) ? uptr(ids) : uptr(bad_pointer()), count, 0};
    ioctl(dev, AGNOCAST_IOC_RELEASE, &arg);
  }

  void introspect() {
    switch (rnd(4)) {
      case 0: {
        agnocast_list_topics arg{some_ptr(4096), some_u32(16), 0, 0, 0};
        ioctl(dev, AGNOCAST_IOC_LIST_TOPICS, &arg);
        break;
      }
      case 1: {
        agnocast_topic_info info{};
        std::strcpy(info.name, kTopics[rnd(std::size(kTopics))]);
        info.publishers = some_ptr(4096);
        info.subscribers = some_ptr(4096);
        info.publisher_capacity = some_u32(20);
        info.subscriber_capacity = some_u32(20);
        ioctl(dev, AGNOCAST_IOC_TOPIC_INFO, &info);
        break;
      }
      case 2: {
        agnocast_list_processes arg{some_ptr(4096), some_u32(100), 0, 0, 0};
        ioctl(dev, AGNOCAST_IOC_LIST_PROCESSES, &arg);
        break;
      }
      default: {
        int fd = open_device(O_RDONLY | O_NONBLOCK);
        if (chance(50))
          (void)!read(fd, arena.base, rnd(1200));
        else
          (void)!read(fd, bad_pointer(), 272 * (1 + rnd(3)));
        struct pollfd p = {fd, POLLIN, 0};
        poll(&p, 1, 0);
        close(fd);
      }
    }
  }

  void step() {
    switch (rnd(20)) {
      case 0:
        garbage();
        break;
      case 1:
        garbage();
        break;
      case 2:
        // Only the main thread re-registers; the other one may briefly use
        // a stale pool address, which the kernel must refuse cleanly.
        if (owns_registration && chance(1)) {
          reg->drop();
          pubs.clear();
          subs.clear();
          entries.clear();
          if (chance(90)) reg->full(dev);
        }
        break;
      case 3:
        add_endpoint(true);
        break;
      case 4:
      case 5:
        add_endpoint(false);
        break;
      case 6:
        remove_endpoint(true);
        break;
      case 7:
        remove_endpoint(false);
        break;
      case 8:
      case 9:
      case 10:
      case 11:
        do_publish();
        break;
      case 12:
      case 13:
        do_receive();
        break;
      case 14:
        do_take();
        break;
      case 15:
      case 16:
        do_release();
        break;
      case 17: {
        agnocast_reclaim rc{some_ptr(4096), static_cast<uint32_t>(rnd(600)), 0, 0, 0};
        ioctl(dev, AGNOCAST_IOC_RECLAIM, &rc);
        break;
      }
      default:
        introspect();
    }
  }
};

std::atomic<bool> stop_threads{false};

void* thread_main(void* p) {
  auto* w = static_cast<Worker*>(p);
  while (!stop_threads.load(std::memory_order_relaxed)) w->step();
  return nullptr;
}

// A worker process: registers (usually), then two threads fuzz until killed.
[[noreturn]] void worker_process(uint64_t seed) {
  int dev = open_device();
  Registration reg;
  std::mt19937_64 rng(seed);
  if (rng() % 10) {
    reg.reserve(dev);
    if (rng() % 10) reg.attach();
  }
  Worker a{std::mt19937_64(seed * 3 + 1), dev, &reg, true, {}, {}, {}, {}};
  Worker b{std::mt19937_64(seed * 5 + 2), dev, &reg, false, {}, {}, {}, {}};
  pthread_t t;
  pthread_create(&t, nullptr, thread_main, &b);
  for (uint64_t i = 0;; i++) {
    a.step();
    // Some workers end on their own, with or without unregistering.
    if (i == 20000 && seed % 3 == 0) _exit(0);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int seconds = argc > 1 ? std::atoi(argv[1]) : 30;
  const int nprocs = argc > 2 ? std::atoi(argv[2]) : 6;
  std::mt19937_64 rng(static_cast<uint64_t>(getpid()) * 7919 + time(nullptr));
  const uint64_t base_seed = rng();
  std::printf("fuzz: %d s, %d processes, seed %llu\n", seconds, nprocs,
              static_cast<unsigned long long>(base_seed));
  std::fflush(stdout);

  std::vector<pid_t> workers(nprocs);
  uint64_t spawned = 0;
  auto spawn = [&](int i) {
    uint64_t seed = base_seed + spawned++;
    pid_t pid = fork();
    if (pid == 0) worker_process(seed);
    workers[i] = pid;
  };
  for (int i = 0; i < nprocs; i++) spawn(i);

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50 + rng() % 200));
    int i = static_cast<int>(rng() % nprocs);
    int status;
    if (waitpid(workers[i], &status, WNOHANG) == 0) {
      kill(workers[i], SIGKILL);
      waitpid(workers[i], &status, 0);
    }
    spawn(i);
  }
  for (pid_t pid : workers) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }

  // Every worker is gone: so must be every registration and every topic.
  int dev = open_device();
  bool clean = eventually([&] {
    agnocast_list_topics lt{0, 0, 0, 0, 0};
    return list_processes(dev).empty() && ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt) == 0 &&
           lt.total == 0;
  });
  size_t records = drain_exit_records(dev).size();
  std::printf("fuzz: %llu worker processes, %zu exit records, state %s\n",
              static_cast<unsigned long long>(spawned), records, clean ? "clean" : "LEFT OVER");
  if (!clean) {
    for (const auto& p : list_processes(dev)) std::printf("  left: pid %d\n", p.pid);
    return 1;
  }
  return 0;
}
