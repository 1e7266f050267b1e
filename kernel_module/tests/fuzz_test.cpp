// Randomized ioctl fuzzer: several processes, two threads each, issue
// commands for a bounded time; the parent kills and respawns workers at
// random.  Around the commands: workers as nobody in and outside group
// agnocast, children forked with the device open (which must own nothing),
// the device file replaced under a thread using it, workers that exec,
// access policies set and removed, a third of the workers in a second IPC
// namespace (and threads visiting the other one), agnocastd (when it is
// beside the fuzzer) reloading access policies on SIGHUP.  A share of the steps are garbage
// (random commands, arguments and bad pointers), a share well-formed and
// stateful (a pool allocator, tagged messages, receives that release what
// they hold), so that every command's success path is reached.  Beside the
// workers, a listener process in each namespace (both at home with
// --no-namespaces) holds callback subscribers that speak the notification
// protocol: each sleeps on its queue and on its process's wake eventfd, and
// on either RECEIVEs until nothing remains.  A well-formed PUBLISH notifies
// them as libagnocast does, with faults on that path: a process killed
// between two of its calls (after PUBLISH, between mq_open and mq_send,
// between two sends; a listener after taking a notification or reading its
// wake eventfd, between RECEIVE and RELEASE, between two RECEIVEs),
// notifications left unsent, reported with NOTIFY_FAILED or not, and
// listeners' queues unlinked under them and at times replaced by another
// queue of that name; a process a fault killed is back at once.  Checked
// while it runs:
//  - every message a subscriber reads carries the tag its publisher wrote:
//    the subscriber's topic, the entry's publisher and address, a checksum;
//    it is read again, unchanged, when the subscriber releases it;
//  - at pauses of every worker, each subscriber's received + unreceived +
//    dropped (the kernel's counters, from TOPIC_INFO) grew by exactly the
//    number of messages published on its topic meanwhile (TAKE passes older
//    entries over uncounted: at most that many for subscribers that took);
//  - messages carry their namespace too, and no worker is ever registered
//    in the namespace it does not live in; nothing a thread visiting the
//    other namespace asks there succeeds;
//  - whatever a listener's subscriber is given (received + unreceived +
//    dropped) it receives or drops within 5 s (kLivenessBound), and while
//    entries wait for it, it receives one within 5 s (drops retire entries
//    too, under a subscriber that sleeps on): checked by the parent every
//    few hundred milliseconds, a lost wake-up fails it;
//  - a command number of the module's type that the UAPI does not define
//    fails with ENOTTY;
//  - the module's parameters (its quotas) cannot change while it runs;
// and at the end that every process and topic is gone in both namespaces,
// that the second namespace's state went with it, that the module's entry
// cache holds no more objects than before, and that agnocastd exits 0.  It prints, per
// command, successes and each errno, and fails if a command never succeeded
// or no wake eventfd ever woke a listener.
// A failure prints the seed and the last operations of the thread that saw
// it.  The VM bed checks the kernel log.
//
// usage: agnocast_fuzz_test [SECONDS [PROCESSES]] [--ops N] [--seed S] [--long]
//                           [--caps | --no-caps] [--namespaces | --no-namespaces]
//                           [--unguided]
//   Runs SECONDS (default 30) and on until N operations (default 0) were
//   issued.  --long: 4 hours and 10^6 operations, unless given otherwise.
//   --seed replays the workers' random choices of an earlier run (the
//   interleaving of processes is the scheduler's) and whether the module is
//   reloaded with small caps ($AGNOCAST_MODULE, a third of the seeds;
//   --caps: always, --no-caps: never).  A third of the workers live in the
//   second IPC namespace; with --no-namespaces threads only visit it.
//   Under kcov (the debug kernel) the steps are guided by the module's
//   edges (kcov_guide.h), which it prints over time; --unguided only counts
//   them.  A guided run replays a seed less closely: kept inputs pass
//   between processes.
#include <dirent.h>
#include <mqueue.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/eventfd.h>
#include <sys/mount.h>
#include <sys/prctl.h>
#include <sys/syscall.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <shared_mutex>
#include <tuple>

#include "kcov_guide.h"
#include "test_util.h"

using namespace agnocast_test;

namespace {

// Rows of the reach table: every command of the UAPI, then outcomes that
// matter beyond a bare success.
enum Row : int {
  kGetVersion,
  kRegister,
  kUnregister,
  kAddPublisher,
  kRemovePublisher,
  kAddSubscriber,
  kRemoveSubscriber,
  kPublish,
  kReclaim,
  kReceive,
  kTake,
  kRelease,
  kListTopics,
  kTopicInfo,
  kListProcesses,
  kShed,
  kSetPolicy,
  kGetPolicy,
  kTopicSchema,
  kNotifyFailed,
  kUnknown,
  kReceiveEntries,   // RECEIVE that returned entries
  kReceiveReleases,  // RECEIVE that released entries
  kTakeEntry,        // TAKE that returned an entry
  kPublishReclaim,   // PUBLISH that returned reclaimable addresses
  kReclaimAddrs,     // RECLAIM that returned addresses
  kShedEntries,      // SHED that took entries
  kRows
};
const char* const kRowNames[kRows] = {"GET_VERSION",
                                      "REGISTER_PROCESS",
                                      "UNREGISTER_PROCESS",
                                      "ADD_PUBLISHER",
                                      "REMOVE_PUBLISHER",
                                      "ADD_SUBSCRIBER",
                                      "REMOVE_SUBSCRIBER",
                                      "PUBLISH",
                                      "RECLAIM",
                                      "RECEIVE",
                                      "TAKE",
                                      "RELEASE",
                                      "LIST_TOPICS",
                                      "TOPIC_INFO",
                                      "LIST_PROCESSES",
                                      "SHED",
                                      "SET_POLICY",
                                      "GET_POLICY",
                                      "TOPIC_SCHEMA",
                                      "NOTIFY_FAILED",
                                      "(unknown command)",
                                      " RECEIVE entries",
                                      " RECEIVE releases",
                                      " TAKE entry",
                                      " PUBLISH reclaim",
                                      " RECLAIM addrs",
                                      " SHED entries"};
const unsigned long kCommands[kUnknown] = {
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
    AGNOCAST_IOC_SHED,
    AGNOCAST_IOC_SET_POLICY,
    AGNOCAST_IOC_GET_POLICY,
    AGNOCAST_IOC_TOPIC_SCHEMA,
    AGNOCAST_IOC_NOTIFY_FAILED,
};
constexpr int kErrnos = 134;  // errno values counted one by one; larger ones share the last
const char* const kTopics[] = {"/a", "/a/b", "/a_b", "/chatter", "/x/y/z", "/x_y/z", "/q"};
constexpr int kNumTopics = static_cast<int>(std::size(kTopics));
constexpr int kMaxProcs = 64;
constexpr int kTakenMax = 8192;
// Workers live in two IPC namespaces: the parent's (0) and a second one (1)
// that a holder process keeps alive for the run.
constexpr int kNamespaces = 2;
// Listeners (struct Listener): processes of callback subscribers that
// speak the notification protocol and nothing else.  What is published to
// them must be received or dropped within kLivenessBound: the mechanism's
// own bound is the next PUBLISH or the module's watchdog
// (AGNOCAST_WAKE_WATCHDOG_MS); this one leaves room for TCG and the debug
// kernel.
constexpr int kListeners = 2;
constexpr int kListenerSubs = 3;
constexpr auto kLivenessBound = std::chrono::milliseconds(5000);

// Where a process kills itself on the message path, between two of its
// system calls.
enum KillPoint : int {
  kAfterPublish,       // PUBLISH listed subscribers, no notification sent
  kAfterOpen,          // a subscriber's queue opened, its notification not sent
  kBetweenSends,       // one notification sent, the next not
  kAfterNotification,  // a listener took a notification, did not RECEIVE
  kAfterWakeEventfd,   // a listener read its wake eventfd, did not RECEIVE
  kBeforeRelease,      // a listener RECEIVEd entries, did not release them
  kBetweenReceives,    // a listener RECEIVEd, entries remain
  kKillPoints
};
const char* const kKillPointNames[kKillPoints] = {"after PUBLISH",
                                                  "between mq_open and mq_send",
                                                  "between two sends",
                                                  "after taking a notification",
                                                  "after reading the wake eventfd",
                                                  "between RECEIVE and RELEASE",
                                                  "between two RECEIVEs"};

// Shared by the parent and every worker (an anonymous shared mapping).
struct Shared {
  std::atomic<uint64_t> count[kRows][kErrnos];
  std::atomic<uint64_t> ops;
  std::atomic<uint64_t> failures;
  std::atomic<uint64_t> verified, rechecked, unverifiable;
  // Successful PUBLISHes per namespace and topic, in total and per worker slot.
  std::atomic<uint64_t> published[kNamespaces][kNumTopics];
  // Bumped when a topic's count may have missed a publish: a worker died
  // between its PUBLISH and the count.  Audits then start that topic afresh.
  std::atomic<uint64_t> uncertain[kNumTopics];
  struct Slot {
    std::atomic<int> pid;
    std::atomic<int> ns;  // the namespace the worker lives and registers in
    std::atomic<int> paused;
    // Per thread: 1 + the topic of a PUBLISH under way (kNumTopics + 1: unknown).
    std::atomic<int> publishing[2];
    std::atomic<uint64_t> published[kNumTopics];
  } slots[kMaxProcs];
  // Subscribers (namespace, topic index + 1) << 32 | id that a TAKE returned
  // an entry to since the last audit.
  std::atomic<uint64_t> taken[kTakenMax];
  std::atomic<bool> taken_overflow;
  std::atomic<bool> pause;
  // Events of the world around the commands.
  std::atomic<uint64_t> forks, device_swaps, members, non_members, execs;
  std::atomic<uint64_t> ns_workers, ns_visits, ns_probes;
  // Listener processes.  Each shows the queues it owns, so that workers can
  // unlink them: (topic + 1) << 32 | subscriber id, 0 for none.
  struct Listener {
    std::atomic<int> pid;
    std::atomic<int> ns;
    std::atomic<uint64_t> queues[kListenerSubs];
    std::atomic<int64_t> last_wake;  // CLOCK_MONOTONIC, ns
  } listeners[kListeners];
  std::atomic<uint64_t> listener_entries, queue_wakes, eventfd_wakes;
  // The faults on the message path: processes killed at each point;
  // notifications sent, left unsent and reported (NOTIFY_FAILED), left
  // unsent silently, reported after a failed mq_open or mq_send; queues
  // unlinked under their listener, and replaced by another one.
  std::atomic<uint64_t> kills[kKillPoints];
  std::atomic<uint64_t> sent, unsent_reported, unsent_silent, send_failed, unlinked, replaced;
  // Descriptors of the two namespaces (/proc/PID/ns/ipc), open in every
  // worker, kept across exec.
  int ns_fd[kNamespaces];
  // kcov's edges of the module and the inputs that found them; with
  // unguided set, edges are counted but no input is replayed.
  CoverageGuide guide;
  bool unguided;
};
Shared* sh;
int shared_fd = -1;  // sh's memfd, kept across exec

uint64_t taken_key(int ns, int topic, uint32_t id) {
  return (static_cast<uint64_t>(ns * kNumTopics + topic) + 1) << 32 | id;
}

void mark_taken(int ns, int topic, uint32_t id) {
  uint64_t key = taken_key(ns, topic, id);
  for (uint64_t i = 0, h = key * 0x9E3779B97F4A7C15ull >> 51; i < kTakenMax; i++) {
    auto& slot = sh->taken[(h + i) % kTakenMax];
    uint64_t cur = 0;
    if (slot.compare_exchange_strong(cur, key) || cur == key) return;
  }
  sh->taken_overflow = true;
}

bool was_taken(int ns, int topic, uint32_t id) {
  uint64_t key = taken_key(ns, topic, id);
  for (uint64_t i = 0, h = key * 0x9E3779B97F4A7C15ull >> 51; i < kTakenMax; i++) {
    uint64_t cur = sh->taken[(h + i) % kTakenMax].load();
    if (cur == key) return true;
    if (cur == 0) return false;
  }
  return true;
}

void make_uncertain(int topic) {
  for (int t = 0; t < kNumTopics; t++)
    if (topic < 0 || topic == t) sh->uncertain[t]++;
}

// A dead worker's publishes under way may have happened uncounted.
void settle_slot(int slot) {
  for (auto& p : sh->slots[slot].publishing) {
    int v = p.exchange(0);
    if (v) make_uncertain(v <= kNumTopics ? v - 1 : -1);
  }
}

int row_of(unsigned long cmd) {
  for (int i = 0; i < kUnknown; i++)
    if (kCommands[i] == cmd) return i;
  return kUnknown;
}

void count(int row, int err) { sh->count[row][std::min(err, kErrnos - 1)]++; }

// A failure outside the message checks; safe in a fork child (no stdio lock).
void report(const char* what, int got, uint64_t seed) {
  sh->failures++;
  char line[256];
  int n = std::snprintf(line, sizeof(line), "fuzz: FAIL (worker seed %llu, pid %d): %s (got %s)\n",
                        static_cast<unsigned long long>(seed), getpid(), what,
                        got ? strerrorname_np(got) : "0");
  if (n > 0) (void)!write(1, line, std::min<size_t>(static_cast<size_t>(n), sizeof(line) - 1));
}

// The name libagnocast gives a callback subscriber's notification queue
// (agnocast/naming.hpp): every '/' of the topic after the first made '_',
// then '@' and the subscriber id.
std::string queue_name(int topic, uint32_t id) {
  std::string name = kTopics[topic];
  std::replace(name.begin() + 1, name.end(), '/', '_');
  return name + "@" + std::to_string(id);
}

uint64_t queue_key(int topic, uint32_t id) { return static_cast<uint64_t>(topic + 1) << 32 | id; }

// Whether a listener of namespace @ns owns the queue of subscriber @id of @topic.
bool listener_queue(int ns, int topic, uint32_t id) {
  for (auto& l : sh->listeners)
    if (l.ns == ns)
      for (auto& q : l.queues)
        if (q == queue_key(topic, id)) return true;
  return false;
}

// The process dies here, at once: no step after this one happens.
[[noreturn]] void die(KillPoint point) {
  sh->kills[point]++;
  kill(getpid(), SIGKILL);
  for (;;) pause();
}

int64_t monotonic_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// A well-formed message: what a publisher writes at the start of a slot.
constexpr uint64_t kMagic = 0x61676e6f66757a7aull;
constexpr uint64_t kSlotBytes = 256;
constexpr uint64_t kSlots = 512;
struct Message {
  uint64_t magic;
  uint32_t topic;
  uint32_t publisher_id;
  int32_t pid;
  uint32_t ns;
  uint64_t seq;
  uint64_t addr;
  uint64_t sum;
};
uint64_t checksum(const Message& m) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (uint64_t v :
       {m.magic, uint64_t{m.topic}, uint64_t{m.publisher_id},
        static_cast<uint64_t>(static_cast<uint32_t>(m.pid)), uint64_t{m.ns}, m.seq, m.addr}) {
    h ^= v;
    h *= 0x100000001b3ull;
    h ^= h >> 29;
  }
  return h;
}

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

struct Ep {
  uint32_t handle = 0;
  uint32_t id = 0;
  int topic = -1;
  uint32_t flags = 0;
  uint64_t seq = 0;
};

struct Held {
  uint32_t handle, sub_id;
  int topic;
  uint64_t entry_id, addr;
};

// What both threads of a worker process share: the registration, its pool
// allocator, the views of other pools and the topic of each handle.  Pool
// memory is touched, and ioctls that can hand back pool addresses issued,
// under the shared lock; re-registering takes it exclusively.
struct Process {
  int dev = -1;
  int slot = 0;
  int ns = 0;         // the namespace it lives in
  bool root = false;  // may change namespace
  uint64_t seed = 0;
  Registration reg;
  std::shared_mutex pool_lock;
  // A topic handle outlives its topic only until another topic takes it, and
  // endpoint ids repeat across topics: a stale endpoint of one topic may thus
  // act on another.  Adding endpoints (and noting their topic) takes this
  // exclusively; the commands whose topic is looked up take it shared, so the
  // handle's topic is the one the kernel acted on.  Taken after pool_lock.
  std::shared_mutex ep_lock;
  // Held by a RECEIVE or TAKE until the pools it was handed are mapped, as
  // the library does: the kernel hands a pool to the process once, and
  // another thread may receive entries in it before it is mapped.
  std::mutex grant_lock;
  std::mutex mu;  // guards what follows
  std::vector<uint64_t> free_slots;
  std::map<uint64_t, uint64_t> views;  // address -> size of mapped pools, ours included
  std::map<uint32_t, int> topic_of;    // topic handle -> topic index

  void reset_pool() {
    free_slots.clear();
    views.clear();
    if (reg.map) {
      for (uint64_t i = kSlots; i-- > 0;) free_slots.push_back(reg.addr + i * kSlotBytes);
      views[reg.addr] = reg.size;
    }
  }
  void reclaimed(const uint64_t* addrs, uint32_t n) {
    std::lock_guard<std::mutex> g(mu);
    for (uint32_t i = 0; i < n; i++) {
      uint64_t a = addrs[i];
      if (reg.map && a >= reg.addr && a < reg.addr + kSlots * kSlotBytes &&
          (a - reg.addr) % kSlotBytes == 0)
        free_slots.push_back(a);
    }
  }
  int topic_for(uint32_t handle) {
    std::lock_guard<std::mutex> g(mu);
    auto it = topic_of.find(handle);
    return it == topic_of.end() ? -1 : it->second;
  }
};

struct OpRecord {
  int row;
  int result;
  uint64_t a, b;
};

int counted_ioctl(int row, int dev, unsigned long cmd, void* arg) {
  int ret = ioctl(dev, cmd, arg) == 0 ? 0 : errno;
  count(row, ret);
  sh->ops++;
  return ret;
}

struct Worker {
  Worker(uint64_t seed, Process* p, bool owner, KcovTrace* trace)
      : rng(seed), proc(p), owns_registration(owner), kcov(trace) {}
  TapedRng rng;
  Process* proc;
  bool owns_registration;
  KcovTrace* kcov;
  Arena arena;
  std::vector<Ep> pubs, subs;
  std::vector<Held> held;
  std::vector<uint64_t> entries;      // ids for garbage releases
  std::map<uint64_t, mqd_t> senders;  // queue_key() -> a queue opened for sending
  OpRecord ring[64] = {};
  uint64_t nops = 0;
  bool reported = false;

  uint64_t rnd(uint64_t n) { return n ? rng() % n : 0; }
  bool chance(int percent) { return rnd(100) < static_cast<uint64_t>(percent); }
  int dev() const { return proc->dev; }

  int call(unsigned long cmd, void* arg, uint64_t a = 0, uint64_t b = 0) {
    int row = row_of(cmd);
    int ret = counted_ioctl(row, dev(), cmd, arg);
    ring[nops++ % std::size(ring)] = {row, ret, a, b};
    return ret;
  }

  void fail(const char* what, uint64_t entry_id, uint64_t addr) {
    sh->failures++;
    if (reported) return;
    reported = true;
    std::printf("fuzz: FAIL (worker seed %llu, pid %d): %s: entry %llu at 0x%llx\n",
                static_cast<unsigned long long>(proc->seed), getpid(), what,
                static_cast<unsigned long long>(entry_id), static_cast<unsigned long long>(addr));
    std::printf("fuzz: the last operations of this thread, oldest first:\n");
    uint64_t n = std::min<uint64_t>(nops, std::size(ring));
    for (uint64_t i = nops - n; i < nops; i++) {
      const OpRecord& r = ring[i % std::size(ring)];
      std::printf("  %-18s 0x%llx 0x%llx -> %s\n", kRowNames[r.row],
                  static_cast<unsigned long long>(r.a), static_cast<unsigned long long>(r.b),
                  r.result ? strerrorname_np(r.result) : "0");
    }
    std::fflush(stdout);
  }

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

  Ep some_endpoint(const std::vector<Ep>& v) {
    if (v.empty() || chance(15)) return {some_u32(8), some_u32(8)};
    return v[rnd(v.size())];
  }

  // --- Reading messages -------------------------------------------------

  // Checks the message of a held entry; false only on a wrong message.
  // Entries of pools this process has no view of cannot be read.
  bool message_ok(int topic, const agnocast_entry& e, bool* read, Message* seen = nullptr) {
    std::lock_guard<std::mutex> g(proc->mu);
    *read = false;
    auto it = proc->views.upper_bound(e.addr);
    if (it == proc->views.begin()) return true;
    --it;
    if (e.addr + sizeof(Message) > it->first + it->second) return true;
    // Only well-formed publishes use slot-aligned addresses.
    if ((e.addr - it->first) % kSlotBytes) return true;
    Message m;
    std::memcpy(&m, reinterpret_cast<const void*>(e.addr), sizeof(m));
    *read = true;
    if (seen) *seen = m;
    return m.magic == kMagic && m.sum == checksum(m) && m.addr == e.addr &&
           static_cast<int>(m.topic) == topic && static_cast<int>(m.ns) == proc->ns &&
           m.publisher_id == e.publisher_id;
  }

  // A wrong message counts only if the entry was held all along: another
  // thread may have released it (a garbage RELEASE may name any id) and its
  // publisher reused the memory.  Releasing it now tells: a held entry is
  // never held again once released.
  void verify(int topic, uint32_t handle, uint32_t sub_id, const agnocast_entry& e, bool recheck) {
    if (topic < 0) return;
    bool read;
    Message m{};
    if (message_ok(topic, e, &read, &m)) {
      if (read)
        (recheck ? sh->rechecked : sh->verified)++;
      else
        sh->unverifiable++;
      return;
    }
    uint64_t id = e.entry_id;
    agnocast_release rel{handle, sub_id, uptr(&id), 1, 0};
    if (call(AGNOCAST_IOC_RELEASE, &rel, handle, id) == 0) {
      fail(recheck ? "a held message changed before its release"
                   : "a received message is not one published on the subscriber's topic",
           e.entry_id, e.addr);
      std::printf(
          "fuzz: expected topic %d, namespace %d, publisher %u; the entry's memory holds: magic "
          "%s, checksum %s, topic %u, namespace %u, publisher %u, pid %d, seq %llu, addr 0x%llx\n",
          topic, proc->ns, e.publisher_id, m.magic == kMagic ? "ok" : "wrong",
          m.sum == checksum(m) ? "ok" : "wrong", m.topic, m.ns, m.publisher_id, m.pid,
          static_cast<unsigned long long>(m.seq), static_cast<unsigned long long>(m.addr));
      std::fflush(stdout);
    }
  }

  // Maps the pools a RECEIVE or TAKE handed over (a garbage step leaves some
  // out).  A view of the slot's previous pool is replaced or, when the new
  // one is left out, removed: what it shows is no longer what entries there
  // hold.  So is this process's own pool when a garbage UNREGISTER let its
  // slot go to another process.
  void map_pools(const agnocast_pool* pools, uint32_t n, bool always) {
    std::lock_guard<std::mutex> g(proc->mu);
    for (uint32_t i = 0; i < n; i++) {
      const agnocast_pool& p = pools[i];
      bool own = proc->reg.map && p.addr == proc->reg.addr;
      auto it = proc->views.find(p.addr);
      if (it != proc->views.end()) {
        if (!own) munmap(reinterpret_cast<void*>(p.addr), it->second);
        proc->views.erase(it);
      }
      if (!own && (always || chance(80))) {
        void* m = mmap(reinterpret_cast<void*>(p.addr), p.size, PROT_READ,
                       MAP_SHARED | MAP_FIXED_NOREPLACE, p.fd, 0);
        if (m == reinterpret_cast<void*>(p.addr))
          proc->views[p.addr] = p.size;
        else if (m != MAP_FAILED)
          munmap(m, p.size);
      }
      close(p.fd);
    }
  }

  // --- Garbage ----------------------------------------------------------

  void garbage() {
    // The kernel sees 32 bits of a command.
    unsigned long cmd = kCommands[rnd(std::size(kCommands))];
    if (chance(10)) cmd = static_cast<uint32_t>(rng());
    if (chance(10)) cmd ^= 1ul << rnd(32);
    // Not these: they would unregister or hand out pools behind the
    // bookkeeping's back.
    if ((cmd == AGNOCAST_IOC_UNREGISTER_PROCESS || cmd == AGNOCAST_IOC_REGISTER_PROCESS) &&
        !chance(10))
      return;
    void* arg;
    if (chance(40)) {
      arg = bad_pointer();
    } else {
      for (int i = 0; i < 4096; i += 8) *reinterpret_cast<uint64_t*>(arena.base + i) = rng();
      arg = arena.base + rnd(512);
    }
    // A garbage PUBLISH that succeeds is of an unknown topic.
    bool pub = cmd == AGNOCAST_IOC_PUBLISH;
    if (pub) publishing() = kNumTopics + 1;
    const int ret = call(cmd, arg, uptr(arg));
    if (ret == 0 && pub) make_uncertain(-1);
    if (pub) publishing() = 0;
    // kCommands holds every command of the UAPI: any other of its type is unknown.
    if (row_of(cmd) == kUnknown && _IOC_TYPE(cmd) == AGNOCAST_IOC_MAGIC && ret != ENOTTY)
      report("a command number the UAPI does not define did not fail with ENOTTY", ret, proc->seed);
  }

  void add_endpoint(bool publisher, bool wellformed) {
    int topic = static_cast<int>(rnd(kNumTopics));
    uint32_t flags = static_cast<uint32_t>(rnd(4));
    if (!publisher && wellformed) flags = static_cast<uint32_t>(rnd(8));
    if (!wellformed && chance(5)) flags = static_cast<uint32_t>(rnd(16));
    auto ep = endpoint(kTopics[topic], 1 + rnd(!wellformed && chance(5) ? 1100 : 8), flags);
    if (!wellformed && chance(5)) ep.node[rnd(sizeof(ep.node))] = static_cast<char>(rng());
    // Some bring the topic's schema (the first to do so sets it).
    static const char kSchema[] = "fuzz message: magic, topic, publisher, pid, seq, addr, sum";
    if (chance(20)) {
      ep.schema = uptr(kSchema);
      ep.schema_size = wellformed ? sizeof(kSchema) : some_u32(8192);
    }
    {
      std::unique_lock<std::shared_mutex> eps(proc->ep_lock);
      if (call(publisher ? AGNOCAST_IOC_ADD_PUBLISHER : AGNOCAST_IOC_ADD_SUBSCRIBER, &ep, topic,
               flags))
        return;
      std::lock_guard<std::mutex> g(proc->mu);
      proc->topic_of[ep.topic_handle] = topic;
    }
    (publisher ? pubs : subs).push_back({ep.topic_handle, ep.id, topic, ep.flags, 0});
  }

  void remove_endpoint(bool publisher) {
    auto& v = publisher ? pubs : subs;
    Ep e = some_endpoint(v);
    agnocast_remove_endpoint rm{e.handle, e.id};
    if (call(publisher ? AGNOCAST_IOC_REMOVE_PUBLISHER : AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm,
             e.handle, e.id) == 0) {
      std::erase_if(v, [&](const Ep& x) { return x.handle == e.handle && x.id == e.id; });
      if (!publisher)
        std::erase_if(held,
                      [&](const Held& h) { return h.handle == e.handle && h.sub_id == e.id; });
    }
  }

  std::atomic<int>& publishing() {
    return sh->slots[proc->slot].publishing[owns_registration ? 0 : 1];
  }

  void published(uint32_t handle, int topic_hint) {
    int topic = topic_hint >= 0 ? topic_hint : proc->topic_for(handle);
    if (topic < 0) {
      // Unknown topic: the counts per topic cannot be trusted until the next audit.
      make_uncertain(-1);
      return;
    }
    sh->published[proc->ns][topic]++;
    sh->slots[proc->slot].published[topic]++;
  }

  void do_publish() {
    Ep e = some_endpoint(pubs);
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    agnocast_publish arg{};
    arg.topic_handle = e.handle;
    arg.publisher_id = e.id;
    // Never slot-aligned: those carry well-formed messages only.
    arg.addr =
        (proc->reg.addr + (chance(90) ? rnd(proc->reg.size ? proc->reg.size : 1) : rng())) | 1;
    arg.bytes = rng();
    arg.wake_ids = some_ptr(4096);
    arg.wake_capacity = chance(80) ? 1024 : some_u32(4);
    arg.reclaim = some_ptr(4096);
    arg.reclaim_capacity = static_cast<uint32_t>(rnd(512));
    arg.reserved = chance(3) ? 1 : 0;
    publishing() = kNumTopics + 1;
    int ret = call(AGNOCAST_IOC_PUBLISH, &arg, e.handle, arg.addr);
    if (ret == 0) published(e.handle, -1);
    publishing() = 0;
    if (ret) return;
    uint64_t addrs[AGNOCAST_RECLAIM_BATCH];
    uint32_t n = std::min<uint32_t>(arg.reclaim_count, AGNOCAST_RECLAIM_BATCH);
    std::memcpy(addrs, reinterpret_cast<const void*>(arg.reclaim), n * sizeof(uint64_t));
    // The kernel writes the wake ids after the addresses: where the two
    // buffers overlap, an "address" may read as the pool's base plus an id,
    // a slot still in use.  Only addresses no wake id overwrote are trusted.
    const uint64_t wake_end = arg.wake_ids + uint64_t{arg.wake_count} * sizeof(uint32_t);
    uint32_t kept = 0;
    for (uint32_t i = 0; i < n; i++) {
      const uint64_t at = arg.reclaim + i * sizeof(uint64_t);
      if (at + sizeof(uint64_t) <= arg.wake_ids || at >= wake_end) addrs[kept++] = addrs[i];
    }
    proc->reclaimed(addrs, kept);
  }

  void do_receive() {
    Ep e = some_endpoint(subs);
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
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    std::unique_lock<std::mutex> grants(proc->grant_lock);
    if (call(AGNOCAST_IOC_RECEIVE, &arg, e.handle, e.id)) return;
    if (arg.release_count) count(kReceiveReleases, 0);
    if (arg.entry_count) count(kReceiveEntries, 0);
    // A "bad" pointer can land in writable memory (the stack's top): the
    // answer is where the kernel wrote it.
    const auto* got = reinterpret_cast<const agnocast_entry*>(arg.entries);
    const auto* got_pools = reinterpret_cast<const agnocast_pool*>(arg.pools);
    check_receive_pools(got_pools, arg.pool_count, got, arg.entry_count);
    map_pools(got_pools, arg.pool_count, false);
    grants.unlock();
    int topic = proc->topic_for(e.handle);
    for (uint32_t i = 0; i < arg.entry_count; i++) {
      entries.push_back(got[i].entry_id);
      verify(topic, e.handle, e.id, got[i], false);
    }
  }

  // Whether one of @n entries lies in @pool.
  static bool holds_one(const agnocast_pool& pool, const agnocast_entry* entries, uint32_t n) {
    return std::any_of(entries, entries + n, [&](const agnocast_entry& e) {
      return e.addr >= pool.addr && e.addr < pool.addr + pool.size;
    });
  }

  // Every pool a RECEIVE hands over holds one of the entries it returned.
  void check_receive_pools(const agnocast_pool* pools, uint32_t pool_count,
                           const agnocast_entry* entries, uint32_t entry_count) {
    for (uint32_t i = 0; i < pool_count; i++) {
      if (!holds_one(pools[i], entries, entry_count))
        fail("RECEIVE handed over a pool none of its entries is in",
             entry_count ? entries[0].entry_id : 0, pools[i].addr);
    }
  }

  void do_take(Ep e, bool wellformed) {
    agnocast_take arg{};
    arg.topic_handle = e.handle;
    arg.subscriber_id = e.id;
    if (!wellformed && chance(3)) arg.flags = 1;
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    std::unique_lock<std::mutex> grants(proc->grant_lock);
    if (call(AGNOCAST_IOC_TAKE, &arg, e.handle, e.id)) return;
    if (arg.pool_count && !holds_one(arg.pool, &arg.entry, arg.entry_count))
      fail("TAKE handed over a pool its entry is not in", arg.entry.entry_id, arg.pool.addr);
    map_pools(&arg.pool, arg.pool_count, wellformed);
    grants.unlock();
    if (!arg.entry_count) return;
    count(kTakeEntry, 0);
    int topic = proc->topic_for(e.handle);
    if (topic < 0)
      sh->taken_overflow = true;
    else
      mark_taken(proc->ns, topic, e.id);
    verify(topic, e.handle, e.id, arg.entry, false);
    if (wellformed)
      held.push_back({e.handle, e.id, topic, arg.entry.entry_id, arg.entry.addr});
    else
      entries.push_back(arg.entry.entry_id);
  }

  void do_release() {
    Ep e = some_endpoint(subs);
    uint64_t ids[3];
    uint32_t count = 1 + static_cast<uint32_t>(rnd(3));
    for (uint32_t i = 0; i < count; i++)
      ids[i] = entries.empty() || chance(20) ? rnd(64) : entries[rnd(entries.size())];
    agnocast_release arg{e.handle, e.id, chance(95) ? uptr(ids) : uptr(bad_pointer()), count, 0};
    call(AGNOCAST_IOC_RELEASE, &arg, e.handle, ids[0]);
  }

  void do_reclaim(bool wellformed) {
    uint64_t addrs[AGNOCAST_RECLAIM_BATCH] = {};
    agnocast_reclaim rc{wellformed ? uptr(addrs) : some_ptr(4096),
                        wellformed ? AGNOCAST_RECLAIM_BATCH : static_cast<uint32_t>(rnd(600)), 0, 0,
                        0};
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    if (call(AGNOCAST_IOC_RECLAIM, &rc, rc.reclaim_capacity) || !rc.reclaim_count) return;
    count(kReclaimAddrs, 0);
    uint32_t n = std::min<uint32_t>(rc.reclaim_count, AGNOCAST_RECLAIM_BATCH);
    std::memcpy(addrs, reinterpret_cast<const void*>(rc.reclaim), n * sizeof(uint64_t));
    proc->reclaimed(addrs, n);
  }

  void do_shed() {
    agnocast_shed arg{};
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    if (call(AGNOCAST_IOC_SHED, chance(95) ? static_cast<void*>(&arg) : bad_pointer()) == 0 &&
        arg.shed)
      count(kShedEntries, 0);
  }

  void do_policy() {
    switch (rnd(6)) {
      case 0: {
        agnocast_policy none{};
        call(AGNOCAST_IOC_SET_POLICY, &none);
        break;
      }
      case 1:
      case 2: {
        // Everyone may use every topic, through one rule or another.
        std::vector<agnocast_policy_rule> rules(1 + rnd(3));
        for (auto& r : rules) {
          std::memset(&r, 0, sizeof(r));
          const char* prefix = rnd(2) ? "" : kTopics[rnd(kNumTopics)];
          std::strcpy(r.prefix, prefix);
          r.match = *prefix ? static_cast<uint32_t>(rnd(3)) : AGNOCAST_MATCH_DESCENDANTS;
          r.flags = AGNOCAST_RULE_PUBLISH | AGNOCAST_RULE_SUBSCRIBE;
          r.first_principal = 0;
          r.publish_count = r.subscribe_count = 1;
        }
        agnocast_principal principals[2] = {anyone_principal(), anyone_principal()};
        agnocast_policy p{
            AGNOCAST_POLICY_PRESENT, static_cast<uint32_t>(rules.size()), 2, 0, uptr(rules.data()),
            uptr(principals)};
        call(AGNOCAST_IOC_SET_POLICY, &p);
        break;
      }
      case 3: {
        // Briefly, one topic refuses root's publishers.
        int ret = set_policy(
            dev(),
            {{kTopics[rnd(kNumTopics)], AGNOCAST_MATCH_EXACT,
              std::vector<agnocast_principal>{group_principal(kAgnocastGroup)}, std::nullopt}});
        count(kSetPolicy, -ret);
        sh->ops++;
        break;
      }
      case 4: {
        agnocast_policy_rule rules[4];
        agnocast_principal principals[8];
        agnocast_policy p{0,
                          static_cast<uint32_t>(rnd(5)),
                          static_cast<uint32_t>(rnd(9)),
                          0,
                          uptr(rules),
                          uptr(principals)};
        call(AGNOCAST_IOC_GET_POLICY, &p);
        break;
      }
      default: {
        // Garbage policies.
        for (int i = 0; i < 4096; i += 8) *reinterpret_cast<uint64_t*>(arena.base + i) = rng();
        agnocast_policy p{static_cast<uint32_t>(rnd(4)),
                          static_cast<uint32_t>(rnd(4)),
                          static_cast<uint32_t>(rnd(4)),
                          0,
                          some_ptr(1024),
                          some_ptr(64)};
        call(AGNOCAST_IOC_SET_POLICY, &p);
      }
    }
  }

  void introspect() {
    switch (rnd(6)) {
      case 0: {
        agnocast_list_topics arg{some_ptr(4096), some_u32(16), 0, 0, 0};
        call(AGNOCAST_IOC_LIST_TOPICS, &arg);
        break;
      }
      case 1: {
        agnocast_topic_info info{};
        std::strcpy(info.name, kTopics[rnd(std::size(kTopics))]);
        info.publishers = some_ptr(4096);
        info.subscribers = some_ptr(4096);
        info.publisher_capacity = some_u32(20);
        info.subscriber_capacity = some_u32(20);
        call(AGNOCAST_IOC_TOPIC_INFO, &info);
        break;
      }
      case 2: {
        agnocast_list_processes arg{some_ptr(4096), some_u32(100), 0, 0, 0};
        call(AGNOCAST_IOC_LIST_PROCESSES, &arg);
        break;
      }
      case 3: {
        agnocast_topic_schema s{};
        std::strcpy(s.name, kTopics[rnd(std::size(kTopics))]);
        s.schema = some_ptr(4096);
        s.capacity = some_u32(64);
        call(AGNOCAST_IOC_TOPIC_SCHEMA, &s);
        break;
      }
      case 4: {
        agnocast_version v{};
        call(AGNOCAST_IOC_GET_VERSION, chance(90) ? static_cast<void*>(&v) : bad_pointer());
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

  // --- Well-formed steps ------------------------------------------------

  void wf_publish() {
    if (pubs.empty()) return add_endpoint(true, true);
    Ep& e = pubs[rnd(pubs.size())];
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    uint64_t addr;
    {
      std::lock_guard<std::mutex> g(proc->mu);
      if (proc->free_slots.empty() || !proc->reg.map) return;
      size_t i = rnd(std::min<size_t>(proc->free_slots.size(), 4));
      addr = proc->free_slots[proc->free_slots.size() - 1 - i];
      proc->free_slots.erase(proc->free_slots.end() - 1 - static_cast<ptrdiff_t>(i));
    }
    const int topic = proc->topic_for(e.handle);
    if (topic < 0) {
      proc->reclaimed(&addr, 1);
      return;
    }
    Message m{kMagic,
              static_cast<uint32_t>(topic),
              e.id,
              getpid(),
              static_cast<uint32_t>(proc->ns),
              ++e.seq,
              addr,
              0};
    m.sum = checksum(m);
    std::memcpy(reinterpret_cast<void*>(addr), &m, sizeof(m));
    static thread_local uint32_t wake[AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX];
    uint64_t reclaim[AGNOCAST_RECLAIM_BATCH];
    agnocast_publish arg{};
    arg.topic_handle = e.handle;
    arg.publisher_id = e.id;
    arg.addr = addr;
    arg.bytes = sizeof(m);
    arg.wake_ids = uptr(wake);
    arg.wake_capacity = AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX;
    arg.reclaim = uptr(reclaim);
    arg.reclaim_capacity = AGNOCAST_RECLAIM_BATCH;
    publishing() = topic + 1;
    int ret = call(AGNOCAST_IOC_PUBLISH, &arg, e.handle, addr);
    if (ret == 0) published(e.handle, topic);
    publishing() = 0;
    if (ret) {
      proc->reclaimed(&addr, 1);
      return;
    }
    if (arg.reclaim_count) count(kPublishReclaim, 0);
    proc->reclaimed(reclaim, arg.reclaim_count);
    notify(e, topic, wake, arg.wake_count);
  }

  // What libagnocast's publisher does after a PUBLISH: a notification to
  // each subscriber it listed, NOTIFY_FAILED for one it could not send.
  // Listeners get the faults: the process dies between two of these calls,
  // or a notification is left unsent, reported or not (the module's
  // watchdog must then wake the subscriber).  The other subscribers have no
  // queue: now and then they get what a missing queue gets.
  void notify(const Ep& e, int topic, const uint32_t* ids, uint32_t n) {
    // Only a PUBLISH that listed a listener is cut short: nobody else waits.
    const bool lists_listener =
        std::any_of(ids, ids + n, [&](uint32_t id) { return listener_queue(proc->ns, topic, id); });
    const int kill_at = lists_listener && !rnd(50) ? static_cast<int>(rnd(3)) : -1;
    if (kill_at == kAfterPublish) die(kAfterPublish);
    for (uint32_t i = 0; i < n; i++) {
      if (i && kill_at == kBetweenSends) die(kBetweenSends);
      if (!listener_queue(proc->ns, topic, ids[i])) {
        if (chance(10) && !send_notification(topic, ids[i], false)) notify_failed(e, ids[i]);
        continue;
      }
      if (chance(3)) {
        sh->unsent_silent++;
      } else if (chance(3)) {
        sh->unsent_reported++;
        notify_failed(e, ids[i]);
      } else if (send_notification(topic, ids[i], kill_at == kAfterOpen)) {
        sh->sent++;
      } else {
        sh->send_failed++;
        notify_failed(e, ids[i]);
      }
    }
  }

  // One notification, through a descriptor kept per subscriber as
  // libagnocast keeps it; false when the queue could not be opened or the
  // send failed other than for a full queue (which holds a wake-up already).
  // @die_before_send: the process dies with the queue open, before the send.
  bool send_notification(int topic, uint32_t id, bool die_before_send) {
    auto it = senders.find(queue_key(topic, id));
    if (it == senders.end()) {
      const mqd_t q = mq_open(queue_name(topic, id).c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (q == -1) return false;
      if (senders.size() >= 32) {
        for (const auto& [key, open] : senders) mq_close(open);
        senders.clear();
      }
      it = senders.emplace(queue_key(topic, id), q).first;
    }
    if (die_before_send) die(kAfterOpen);
    const char byte = 0;
    if (mq_send(it->second, &byte, 1, 0) == 0 || errno == EAGAIN) return true;
    mq_close(it->second);
    senders.erase(it);
    return false;
  }

  void notify_failed(const Ep& e, uint32_t subscriber_id) {
    agnocast_notify_failed arg{e.handle, e.id, subscriber_id, 0};
    call(AGNOCAST_IOC_NOTIFY_FAILED, &arg, e.handle, subscriber_id);
  }

  // A listener's queue unlinked under it and, half the time, another one
  // made under its name, which its publishers then open (libagnocast never
  // makes its queue again): the listener's wake eventfd must still wake it.
  void unlink_listener_queue() {
    const auto& l = sh->listeners[rnd(kListeners)];
    const uint64_t key = l.queues[rnd(kListenerSubs)];
    if (l.ns != proc->ns || !key) return;
    const std::string name =
        queue_name(static_cast<int>((key >> 32) - 1), static_cast<uint32_t>(key));
    if (mq_unlink(name.c_str()) == 0) sh->unlinked++;
    if (chance(50)) return;
    mq_attr attr{};
    attr.mq_maxmsg = 1 + static_cast<long>(rnd(2));
    attr.mq_msgsize = 1;
    const mqd_t q =
        mq_open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NONBLOCK | O_CLOEXEC, 0622, &attr);
    if (q == -1) return;
    sh->replaced++;
    mq_close(q);
  }

  void wf_receive() {
    if (subs.empty()) return add_endpoint(false, true);
    Ep e = subs[rnd(subs.size())];
    if (e.flags & AGNOCAST_POLLING) return wf_take(e);
    uint64_t rel[8];
    std::vector<Held> released;
    const size_t max_release = chance(20) ? 0 : 8;
    for (const Held& h : held)
      if (h.handle == e.handle && h.sub_id == e.id && released.size() < max_release)
        released.push_back(h);
    // Read the held messages once more before they go back.
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    std::vector<bool> wrong(released.size());
    for (size_t i = 0; i < released.size(); i++) {
      rel[i] = released[i].entry_id;
      wrong[i] = !held_ok(released[i]);
    }
    agnocast_entry ents[8];
    agnocast_pool pools[AGNOCAST_RECEIVE_POOLS_MAX];
    agnocast_receive arg{};
    arg.topic_handle = e.handle;
    arg.subscriber_id = e.id;
    arg.entries = uptr(ents);
    arg.pools = uptr(pools);
    arg.entry_capacity = 1 + static_cast<uint32_t>(rnd(8));
    arg.pool_capacity = AGNOCAST_RECEIVE_POOLS_MAX;
    arg.release_count = static_cast<uint32_t>(released.size());
    arg.release_ids = uptr(rel);
    std::unique_lock<std::mutex> grants(proc->grant_lock);
    int ret = call(AGNOCAST_IOC_RECEIVE, &arg, e.handle, arg.release_count);
    if (ret == 0 || ret == ENOENT || ret == ESRCH || ret == EXDEV) {
      // Released now, or not held any more (removed by another thread).
      std::erase_if(held, [&](const Held& h) {
        for (const Held& r : released)
          if (r.handle == h.handle && r.sub_id == h.sub_id && r.entry_id == h.entry_id) return true;
        return false;
      });
    }
    if (ret) return;
    for (size_t i = 0; i < released.size(); i++)
      if (wrong[i]) {
        fail("a held message changed before its release", rel[i], released[i].addr);
        show_memory(released[i].topic, released[i].addr);
      }
    if (arg.release_count) count(kReceiveReleases, 0);
    if (arg.entry_count) count(kReceiveEntries, 0);
    check_receive_pools(pools, arg.pool_count, ents, arg.entry_count);
    map_pools(pools, arg.pool_count, true);
    grants.unlock();
    const int topic = proc->topic_for(e.handle);
    for (uint32_t i = 0; i < arg.entry_count; i++) {
      held.push_back({e.handle, e.id, topic, ents[i].entry_id, ents[i].addr});
      // Checked once the pools are mapped; kept for the check at release.
      verify(topic, e.handle, e.id, ents[i], false);
    }
  }

  // The message of a held entry is (still) one of its topic.
  bool held_ok(const Held& h) {
    std::lock_guard<std::mutex> g(proc->mu);
    auto it = proc->views.upper_bound(h.addr);
    if (it == proc->views.begin()) return true;
    --it;
    if (h.addr + sizeof(Message) > it->first + it->second || (h.addr - it->first) % kSlotBytes)
      return true;
    Message m;
    std::memcpy(&m, reinterpret_cast<const void*>(h.addr), sizeof(m));
    sh->rechecked++;
    return m.magic == kMagic && m.sum == checksum(m) && m.addr == h.addr &&
           static_cast<int>(m.topic) == h.topic && static_cast<int>(m.ns) == proc->ns;
  }

  // What a wrong held message's memory holds now (if still mapped).
  void show_memory(int topic, uint64_t addr) {
    std::lock_guard<std::mutex> g(proc->mu);
    auto it = proc->views.upper_bound(addr);
    if (it == proc->views.begin()) return;
    --it;
    if (addr + sizeof(Message) > it->first + it->second) return;
    Message m;
    std::memcpy(&m, reinterpret_cast<const void*>(addr), sizeof(m));
    std::printf(
        "fuzz: expected topic %d, namespace %d; the memory holds: topic %u, namespace %u, "
        "publisher %u, pid %d, seq %llu, addr 0x%llx\n",
        topic, proc->ns, m.topic, m.ns, m.publisher_id, m.pid,
        static_cast<unsigned long long>(m.seq), static_cast<unsigned long long>(m.addr));
    std::fflush(stdout);
  }

  void wf_take(Ep e) { do_take(e, true); }

  void wf_release() {
    if (held.empty()) return;
    const Held first = held[rnd(held.size())];
    std::vector<Held> released;
    for (const Held& h : held)
      if (h.handle == first.handle && h.sub_id == first.sub_id && released.size() < 4)
        released.push_back(h);
    std::vector<uint64_t> ids;
    std::shared_lock<std::shared_mutex> lock(proc->pool_lock);
    std::shared_lock<std::shared_mutex> eps(proc->ep_lock);
    bool wrong = false;
    for (const Held& h : released) {
      ids.push_back(h.entry_id);
      wrong |= !held_ok(h);
    }
    agnocast_release arg{first.handle, first.sub_id, uptr(ids.data()),
                         static_cast<uint32_t>(ids.size()), 0};
    int ret = call(AGNOCAST_IOC_RELEASE, &arg, first.handle, ids[0]);
    if (ret == 0 && wrong) fail("a held message changed before its release", ids[0], first.addr);
    std::erase_if(held, [&](const Held& h) {
      for (const Held& r : released)
        if (r.handle == h.handle && r.sub_id == h.sub_id && r.entry_id == h.entry_id) return true;
      return false;
    });
  }

  // The device file goes away under the other thread: its descriptor
  // number now names a new open file of the device.  Registration belongs to
  // the process, not the file, so nothing else changes.
  void swap_device() {
    int fd = open_device();
    if (fd < 0) return;  // a worker outside group agnocast cannot reopen it
    dup2(fd, proc->dev);
    close(fd);
    sh->device_swaps++;
  }

  // A child forked with the device open is a process of its own: not
  // registered, owner of none of its parent's endpoints or entries.
  void fork_child() {
    Ep pub = pubs.empty() ? Ep{} : pubs[0];
    Ep sub = subs.empty() ? Ep{} : subs[0];
    uint64_t held_id = held.empty() ? 0 : held[0].entry_id;
    bool has_held = !held.empty();
    int dev = proc->dev;
    uint64_t seed = proc->seed;
    sh->forks++;
    pid_t pid = fork();
    if (pid == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      auto expect = [&](int row, unsigned long cmd, void* arg, const char* what) {
        int ret = counted_ioctl(row, dev, cmd, arg);
        if (ret != ESRCH && !(ret == EACCES && row == kAddSubscriber)) report(what, ret, seed);
      };
      agnocast_add_endpoint ep = endpoint(kTopics[0], 1);
      expect(kAddSubscriber, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep,
             "a fork child, not registered, added a subscriber");
      if (!pubs.empty()) {
        agnocast_publish arg{};
        arg.topic_handle = pub.handle;
        arg.publisher_id = pub.id;
        arg.addr = proc->reg.addr;
        arg.wake_ids = uptr(arena.base);
        arg.wake_capacity = 1;
        expect(kPublish, AGNOCAST_IOC_PUBLISH, &arg,
               "a fork child published on its parent's publisher");
      }
      if (has_held) {
        agnocast_release rel{sub.handle, sub.id, uptr(&held_id), 1, 0};
        expect(kRelease, AGNOCAST_IOC_RELEASE, &rel, "a fork child released its parent's entry");
      }
      // Registering and leaving without a word: the kernel cleans up.
      agnocast_register_process reg{};
      reg.pool_fd = -1;
      if (counted_ioctl(kRegister, dev, AGNOCAST_IOC_REGISTER_PROCESS, &reg) == 0) {
        agnocast_add_endpoint ep2 = endpoint(kTopics[rnd(kNumTopics)], 1 + rnd(4));
        counted_ioctl(kAddPublisher, dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep2);
      }
      _exit(0);
    }
    if (pid > 0) waitpid(pid, nullptr, 0);
  }

  // The worker execs a new worker image in place (same pid): the kernel
  // drops what the old image held.  Outside group agnocast it could not
  // reopen the device, so it does not.
  void exec_self() {
    if (proc->seed % 8 == 6) return;
    char slot[16], seed[32], fd[16];
    std::snprintf(slot, sizeof(slot), "%d", proc->slot);
    std::snprintf(seed, sizeof(seed), "%llu",
                  static_cast<unsigned long long>(proc->seed * 0x9E3779B97F4A7C15ull + 7));
    std::snprintf(fd, sizeof(fd), "%d", shared_fd);
    sh->execs++;
    execl("/proc/self/exe", "agnocast_fuzz_test", "--worker", slot, seed, fd,
          static_cast<char*>(nullptr));
    sh->execs--;
  }

  // A visit to the other namespace by one thread while the other stays
  // home: the process is registered (if at all) at home, so nothing it asks
  // there may succeed or show it.
  void visit_other_ns() {
    const int other = 1 - proc->ns;
    if (!proc->root || sh->ns_fd[other] < 0) return;
    if (setns(sh->ns_fd[other], CLONE_NEWIPC)) {
      report("setns to the other IPC namespace failed", errno, proc->seed);
      return;
    }
    sh->ns_visits++;
    auto refused = [&](unsigned long cmd, void* arg, const char* what) {
      sh->ns_probes++;
      if (call(cmd, arg, 0xe0, static_cast<uint64_t>(other)) == 0) report(what, 0, proc->seed);
    };
    agnocast_add_endpoint ep = endpoint(kTopics[rnd(kNumTopics)], 1);
    refused(AGNOCAST_IOC_ADD_SUBSCRIBER, &ep,
            "a process registered in one IPC namespace added a subscriber in another");
    if (!pubs.empty()) {
      agnocast_publish arg{};
      arg.topic_handle = pubs[0].handle;
      arg.publisher_id = pubs[0].id;
      arg.addr = proc->reg.addr;
      arg.bytes = sizeof(Message);
      arg.wake_ids = uptr(arena.base);
      arg.wake_capacity = 1;
      refused(AGNOCAST_IOC_PUBLISH, &arg,
              "a publisher of one IPC namespace published from another");
    }
    if (!subs.empty()) {
      agnocast_entry ents[4];
      agnocast_pool pools[4];
      agnocast_receive arg{};
      arg.topic_handle = subs[0].handle;
      arg.subscriber_id = subs[0].id;
      arg.entries = uptr(ents);
      arg.pools = uptr(pools);
      arg.entry_capacity = 4;
      arg.pool_capacity = 4;
      refused(AGNOCAST_IOC_RECEIVE, &arg,
              "a subscriber of one IPC namespace received from another");
    }
    for (const auto& p : list_processes(dev()))
      if (p.pid == getpid())
        report("a process is listed in an IPC namespace it never registered in", 0, proc->seed);
    if (setns(sh->ns_fd[proc->ns], CLONE_NEWIPC)) {
      report("setns back to the worker's IPC namespace failed", errno, proc->seed);
      _exit(3);
    }
  }

  void reregister() {
    std::unique_lock<std::shared_mutex> lock(proc->pool_lock);
    std::unique_lock<std::shared_mutex> eps(proc->ep_lock);
    std::lock_guard<std::mutex> g(proc->mu);
    count(kUnregister, -ioc0(proc->dev, AGNOCAST_IOC_UNREGISTER_PROCESS));
    sh->ops++;
    if (proc->reg.map) munmap(proc->reg.map, proc->reg.size);
    if (proc->reg.memfd >= 0) close(proc->reg.memfd);
    for (auto& [addr, size] : proc->views)
      if (addr != proc->reg.addr) munmap(reinterpret_cast<void*>(addr), size);
    proc->reg = Registration{};
    proc->topic_of.clear();
    pubs.clear();
    subs.clear();
    held.clear();
    entries.clear();
    if (chance(90)) register_process(proc, true);
    proc->reset_pool();
  }

  static void register_process(Process* p, bool attach) {
    int ret = p->reg.reserve(p->dev);
    count(kRegister, -ret);
    sh->ops++;
    if (ret || !attach) return;
    ret = p->reg.attach();
    count(kRegister, -ret);
    sh->ops++;
  }

  void step() {
    if (chance(40)) {
      // Well-formed: the paths that reach deep.
      switch (rnd(16)) {
        case 0:
          return add_endpoint(true, true);
        case 1:
        case 2:
          return add_endpoint(false, true);
        case 3:
        case 4:
        case 5:
        case 6:
          return wf_publish();
        case 7:
        case 8:
        case 9:
        case 10:
          return wf_receive();
        case 11:
          return wf_release();
        case 12:
          return do_reclaim(true);
        case 13:
          return do_shed();
        default:
          if (!subs.empty() && chance(50)) return do_take(subs[rnd(subs.size())], true);
          return wf_publish();
      }
    }
    switch (rnd(21)) {
      case 0:
      case 1:
        return garbage();
      case 2:
        // Only the main thread re-registers; the other one may briefly use
        // a stale pool address, which the kernel must refuse cleanly.
        if (owns_registration && chance(10)) return reregister();
        if (chance(2)) return swap_device();
        if (owns_registration && chance(2)) return fork_child();
        if (owns_registration && chance(1)) return exec_self();
        if (owns_registration && chance(4)) return visit_other_ns();
        if (chance(3)) return unlink_listener_queue();
        return;
      case 3:
        return add_endpoint(true, false);
      case 4:
      case 5:
        return add_endpoint(false, false);
      case 6:
        return remove_endpoint(true);
      case 7:
        return remove_endpoint(false);
      case 8:
      case 9:
        return do_publish();
      case 10:
      case 11:
        return do_receive();
      case 12:
        return do_take(some_endpoint(subs), false);
      case 13:
      case 14:
        return do_release();
      case 15:
        return do_reclaim(false);
      case 16:
        return do_shed();
      case 17:
        if (chance(30)) do_policy();
        return;
      default:
        return introspect();
    }
  }

  // One step; under kcov (kcov_guide.h) a quarter of them replay a kept
  // input, changed a little, and a step that makes a new edge is kept.
  void guided_step() {
    if (!kcov->start()) {
      rng.begin();
      return step();
    }
    std::vector<uint64_t> replay;
    if (!sh->unguided && rng.fresh() % 4 == 0) replay = mutate(sh->guide.pick(rng.fresh()), rng);
    rng.begin(std::move(replay));
    step();
    if (sh->guide.merge(kcov->pcs())) sh->guide.keep(rng.tape());
  }

  // Pauses while the parent audits.
  void maybe_pause() {
    if (!sh->pause.load(std::memory_order_relaxed)) return;
    auto& slot = sh->slots[proc->slot];
    slot.paused++;
    while (sh->pause.load()) usleep(500);
    slot.paused--;
  }
};

std::atomic<bool> stop_threads{false};

void* thread_main(void* p) {
  auto* w = static_cast<Worker*>(p);
  while (!stop_threads.load(std::memory_order_relaxed)) {
    w->maybe_pause();
    w->guided_step();
  }
  return nullptr;
}

// Mostly root; some are nobody in group agnocast, who may open the device;
// some are nobody outside it, who may not, but use a descriptor root opened
// for them (a descriptor carries its opener's rights).
void identity(Process* proc, uint64_t seed) {
  if ((proc->dev = open_device()) < 0) {
    report("root could not open the device", errno, seed);
  } else if (seed % 8 == 5) {
    close(proc->dev);
    if (!become(kNobody, kNobody, {kAgnocastGroup})) report("could not become nobody", errno, seed);
    proc->dev = open_device();
    if (proc->dev < 0) report("a member of group agnocast could not open the device", errno, seed);
    sh->members++;
  } else if (seed % 8 == 6) {
    if (!become(kNobody, kNobody, {})) report("could not become nobody", errno, seed);
    int fd = open_device();
    if (fd >= 0 || errno != EACCES)
      report("a process outside group agnocast opened the device", fd >= 0 ? 0 : errno, seed);
    if (fd >= 0) close(fd);
    sh->non_members++;
  }
}

// A worker process: registers (usually), then two threads fuzz until killed.
[[noreturn]] void worker_process(int slot, uint64_t seed, bool execed) {
  sh->slots[slot].pid = getpid();
  // Opened while still root, one per thread.
  auto* kcov_a = new KcovTrace;
  auto* kcov_b = new KcovTrace;
  auto* proc = new Process;
  proc->slot = slot;
  proc->seed = seed;
  proc->ns = sh->slots[slot].ns;
  // The second namespace's workers enter it first (an exec'd one is there).
  if (!execed && proc->ns) {
    if (setns(sh->ns_fd[proc->ns], CLONE_NEWIPC))
      report("could not enter the second IPC namespace", errno, seed);
    sh->ns_workers++;
  }
  if (execed) {
    // The old image's other thread died anywhere, maybe mid-publish; its
    // pause is void.  Its registration must go, soon.
    settle_slot(slot);
    make_uncertain(-1);
    sh->slots[slot].paused = 0;
    proc->dev = open_device();
    if (!eventually([&] { return !process_listed(proc->dev, getpid()); }))
      report("a process that exec'd is still registered", 0, seed);
  } else {
    identity(proc, seed);
  }
  proc->root = geteuid() == 0;
  std::mt19937_64 rng(seed);
  if (rng() % 10) Worker::register_process(proc, rng() % 10 != 0);
  proc->reset_pool();
  auto* a = new Worker(seed * 3 + 1, proc, true, kcov_a);
  auto* b = new Worker(seed * 5 + 2, proc, false, kcov_b);
  pthread_t t;
  pthread_create(&t, nullptr, thread_main, b);
  for (uint64_t i = 0;; i++) {
    a->maybe_pause();
    a->guided_step();
    // Some workers end on their own, with or without unregistering.
    if (i == 5000 && seed % 3 == 0) {
      if (seed % 2) counted_ioctl(kUnregister, proc->dev, AGNOCAST_IOC_UNREGISTER_PROCESS, nullptr);
      _exit(0);
    }
  }
}

// --- Listeners ---------------------------------------------------------------

// A process of callback subscribers that does for them what libagnocast's
// executor does, and nothing else: it sleeps on their queues and on its
// wake eventfd (REGISTER_PROCESS with AGNOCAST_REGISTER_WAKE_EVENTFD), and
// on either RECEIVEs until nothing remains, taking one notification before
// or after.  The parent checks that nothing published to them waits
// (check_liveness()).  It dies now and then between two of its calls, and
// a subscriber of it goes with its queue and another one comes.
struct Listener {
  struct Sub {
    Ep ep;  // ep.topic < 0: none
    mqd_t queue = -1;
    std::vector<uint64_t> held;  // released by the next RECEIVE, or by RELEASE at once
  };

  Listener(int slot, uint64_t seed) : rng(seed), seed(seed), shown(sh->listeners[slot]) {}
  std::mt19937_64 rng;
  uint64_t seed;
  Shared::Listener& shown;
  int dev = -1;
  int wake = -1;
  bool drain_first = false;     // takes the notification before its RECEIVEs
  bool batch_releases = false;  // releases within the next RECEIVE, as libagnocast does
  Sub subs[kListenerSubs];

  uint64_t rnd(uint64_t n) { return n ? rng() % n : 0; }
  bool chance(int percent) { return rnd(100) < static_cast<uint64_t>(percent); }
  void maybe_die(KillPoint point) {
    if (!rnd(100)) die(point);
  }

  [[noreturn]] void run(int ns) {
    shown.pid = getpid();
    if (!start(ns)) {
      report("a listener could not open the device and register with its wake eventfd", errno,
             seed);
      _exit(0);
    }
    drain_first = chance(50);
    batch_releases = chance(50);
    const int wanted = 1 + static_cast<int>(rnd(kListenerSubs));
    for (int64_t next_change = 0;;) {
      // The missing subscribers come (again, when a policy or a cap refused
      // them); now and then one goes with its queue.
      if (monotonic_ns() >= next_change) {
        next_change = monotonic_ns() + 100000000;
        for (int i = 0; i < wanted; i++) {
          if (subs[i].ep.topic < 0)
            add_subscriber(i);
          else if (!rnd(300))
            remove_subscriber(i);
        }
      }
      wait();
    }
  }

  // The wake eventfd goes with the first step of REGISTER_PROCESS, or with
  // a repeated first step, before any subscriber.
  bool start(int ns) {
    if (ns && setns(sh->ns_fd[ns], CLONE_NEWIPC)) return false;
    dev = open_device();
    wake = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (dev < 0 || wake < 0) return false;
    const bool at_once = chance(70);
    return register_step(at_once) == 0 && (at_once || register_step(true) == 0);
  }

  int register_step(bool with_wake_eventfd) {
    agnocast_register_process reg{};
    reg.pool_fd = -1;
    if (with_wake_eventfd) {
      reg.flags = AGNOCAST_REGISTER_WAKE_EVENTFD;
      reg.wake_fd = wake;
    }
    return counted_ioctl(kRegister, dev, AGNOCAST_IOC_REGISTER_PROCESS, &reg);
  }

  void add_subscriber(int i) {
    Sub& s = subs[i];
    const int topic = static_cast<int>(rnd(kNumTopics));
    const uint32_t flags = chance(75) ? AGNOCAST_WAKE_ONCE : 0;
    auto ep = endpoint(kTopics[topic], 1 + static_cast<uint32_t>(rnd(8)), flags, "listener");
    if (counted_ioctl(kAddSubscriber, dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep)) return;
    s.ep = {ep.topic_handle, ep.id, topic, flags, 0};
    // Made as libagnocast makes it: a queue there under its name is a leftover.
    const std::string name = queue_name(topic, ep.id);
    mq_attr attr{};
    // Taking the notification after the RECEIVEs needs room for two.
    attr.mq_maxmsg = static_cast<long>(drain_first ? 1 + rnd(3) : 2 + rnd(2));
    attr.mq_msgsize = 1;
    for (int tries = 0; tries < 3 && s.queue == -1; tries++) {
      s.queue =
          mq_open(name.c_str(), O_RDONLY | O_CREAT | O_EXCL | O_NONBLOCK | O_CLOEXEC, 0622, &attr);
      if (s.queue == -1 && errno == EEXIST) mq_unlink(name.c_str());
    }
    if (s.queue == -1 || fchmod(s.queue, 0622)) {
      report("a listener could not make its queue", errno, seed);
      remove_subscriber(i);
      return;
    }
    shown.queues[i] = queue_key(topic, ep.id);
    // Listed before its queue was there, it may have missed its notification.
    receive_all(s);
  }

  void remove_subscriber(int i) {
    Sub& s = subs[i];
    shown.queues[i] = 0;
    if (s.queue != -1) {
      mq_close(s.queue);
      mq_unlink(queue_name(s.ep.topic, s.ep.id).c_str());
    }
    agnocast_remove_endpoint rm{s.ep.handle, s.ep.id};
    counted_ioctl(kRemoveSubscriber, dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm);
    s = Sub{};
  }

  // Sleeps until a queue or the wake eventfd says there is something, and
  // receives it.
  void wait() {
    pollfd fds[kListenerSubs + 1] = {{wake, POLLIN, 0}};
    int sub_of[kListenerSubs + 1];
    nfds_t n = 1;
    for (int i = 0; i < kListenerSubs; i++) {
      if (subs[i].ep.topic < 0) continue;
      sub_of[n] = i;
      fds[n++] = {subs[i].queue, POLLIN, 0};
    }
    if (poll(fds, n, 100) <= 0) return;
    shown.last_wake = monotonic_ns();
    uint64_t signals;
    if ((fds[0].revents & POLLIN) && read(wake, &signals, sizeof(signals)) == sizeof(signals)) {
      sh->eventfd_wakes++;
      maybe_die(kAfterWakeEventfd);
      for (Sub& s : subs)
        if (s.ep.topic >= 0) receive_all(s);
    }
    for (nfds_t k = 1; k < n; k++) {
      if (!(fds[k].revents & POLLIN)) continue;
      Sub& s = subs[sub_of[k]];
      char byte;
      sh->queue_wakes++;
      if (drain_first) {
        (void)!mq_receive(s.queue, &byte, 1, nullptr);
        maybe_die(kAfterNotification);
      }
      receive_all(s);
      if (!drain_first) (void)!mq_receive(s.queue, &byte, 1, nullptr);
    }
  }

  // RECEIVEs until nothing remains.
  void receive_all(Sub& s) {
    for (;;) {
      agnocast_entry ents[4];
      agnocast_pool pools[AGNOCAST_RECEIVE_POOLS_MAX];
      agnocast_receive arg{};
      arg.topic_handle = s.ep.handle;
      arg.subscriber_id = s.ep.id;
      arg.entries = uptr(ents);
      arg.pools = uptr(pools);
      arg.entry_capacity = 1 + static_cast<uint32_t>(rnd(std::size(ents)));
      arg.pool_capacity = AGNOCAST_RECEIVE_POOLS_MAX;
      arg.release_ids = uptr(s.held.data());
      arg.release_count = static_cast<uint32_t>(s.held.size());
      if (int ret = counted_ioctl(kReceive, dev, AGNOCAST_IOC_RECEIVE, &arg)) {
        report("a listener's RECEIVE failed", ret, seed);
        return;
      }
      if (arg.release_count) count(kReceiveReleases, 0);
      if (arg.entry_count) count(kReceiveEntries, 0);
      s.held.clear();
      for (uint32_t i = 0; i < arg.pool_count; i++) close(pools[i].fd);
      for (uint32_t i = 0; i < arg.entry_count; i++) s.held.push_back(ents[i].entry_id);
      sh->listener_entries += arg.entry_count;
      if (!batch_releases && !s.held.empty()) {
        maybe_die(kBeforeRelease);
        agnocast_release rel{s.ep.handle, s.ep.id, uptr(s.held.data()),
                             static_cast<uint32_t>(s.held.size()), 0};
        if (int ret = counted_ioctl(kRelease, dev, AGNOCAST_IOC_RELEASE, &rel))
          report("a listener's RELEASE failed", ret, seed);
        s.held.clear();
      }
      if (!arg.remaining) return;
      maybe_die(kBetweenReceives);
    }
  }
};

// --- The parent's audit of the kernel's counters ---------------------------

struct SubSnapshot {
  int pid;
  uint32_t flags;
  uint64_t total;  // received + unreceived + dropped
  uint64_t published;
  uint64_t uncertain;
  uint64_t own;  // published by the owner's worker slot, or ~0
};
long slab_objects(std::string* note, bool shrink = true);

// (namespace, topic, subscriber id)
using SubKey = std::tuple<int, int, uint32_t>;
std::map<SubKey, SubSnapshot> last_audit;
uint64_t audits = 0, audit_checks = 0, audits_skipped = 0, isolation_checks = 0;
long slab_peak = -1;

// The parent moves between the namespaces to look at each; its descriptor
// of the device acts in the namespace it is in.
bool enter_ns(int ns) { return sh->ns_fd[ns] >= 0 && setns(sh->ns_fd[ns], CLONE_NEWIPC) == 0; }

// One namespace's subscribers, and that no worker of the other one is
// registered here.
bool audit_ns(int dev, int ns, const std::vector<pid_t>& workers,
              std::map<SubKey, SubSnapshot>& now) {
  bool ok = true;
  for (const auto& p : list_processes(dev)) {
    for (size_t w = 0; w < workers.size(); w++) {
      if (sh->slots[w].pid != p.pid) continue;
      isolation_checks++;
      if (sh->slots[w].ns != ns) {
        std::printf("fuzz: FAIL: worker %d of IPC namespace %d is registered in namespace %d\n",
                    p.pid, sh->slots[w].ns.load(), ns);
        ok = false;
      }
    }
  }
  std::vector<agnocast_subscriber_info> subs(2048);
  for (int t = 0; t < kNumTopics; t++) {
    agnocast_topic_info info{};
    std::strcpy(info.name, kTopics[t]);
    info.subscribers = uptr(subs.data());
    info.subscriber_capacity = static_cast<uint32_t>(subs.size());
    if (ioc(dev, AGNOCAST_IOC_TOPIC_INFO, &info)) continue;
    uint64_t published = sh->published[ns][t], uncertain = sh->uncertain[t];
    for (uint32_t i = 0; i < std::min<uint32_t>(info.subscriber_total, 2048); i++) {
      const auto& s = subs[i];
      uint64_t own = ~0ull;
      for (size_t w = 0; w < workers.size(); w++)
        if (sh->slots[w].pid == s.pid && sh->slots[w].ns == ns) own = sh->slots[w].published[t];
      SubSnapshot snap{s.pid,     s.flags,   s.received + s.unreceived + s.dropped,
                       published, uncertain, own};
      auto prev = last_audit.find({ns, t, s.id});
      now[{ns, t, s.id}] = snap;
      if (prev == last_audit.end() || prev->second.pid != s.pid ||
          prev->second.uncertain != uncertain)
        continue;
      uint64_t expect = published - prev->second.published;
      if (s.flags & AGNOCAST_IGNORE_LOCAL) {
        if (own == ~0ull || prev->second.own == ~0ull) continue;
        expect -= own - prev->second.own;
      }
      // Signed: TAKE passes older unreceived entries over uncounted.
      auto got = static_cast<int64_t>(snap.total - prev->second.total);
      bool took = sh->taken_overflow || was_taken(ns, t, s.id);
      audit_checks++;
      if (took ? got > static_cast<int64_t>(expect) : got != static_cast<int64_t>(expect)) {
        std::printf(
            "fuzz: FAIL: %s subscriber %u of IPC namespace %d (pid %d, flags %u): received + "
            "unreceived + dropped grew by %lld, %llu published meanwhile%s\n",
            kTopics[t], s.id, ns, s.pid, s.flags, static_cast<long long>(got),
            static_cast<unsigned long long>(expect), took ? " (it took)" : "");
        ok = false;
      }
    }
  }
  return ok;
}

bool audit(int dev, const std::vector<pid_t>& workers) {
  sh->pause = true;
  bool all = eventually(
      [&] {
        for (size_t i = 0; i < workers.size(); i++) {
          siginfo_t info{};
          if (waitid(P_PID, static_cast<id_t>(workers[i]), &info, WEXITED | WNOHANG | WNOWAIT) ||
              info.si_pid) {
            settle_slot(static_cast<int>(i));  // dead
            continue;
          }
          if (sh->slots[i].paused.load() < 2) return false;
        }
        return true;
      },
      3000);
  if (!all) {
    sh->pause = false;
    audits_skipped++;
    return true;
  }
  // Everyone is between steps: the counts are settled.
  bool ok = true;
  std::map<SubKey, SubSnapshot> now;
  for (int ns = 0; ns < kNamespaces; ns++)
    if (enter_ns(ns)) ok &= audit_ns(dev, ns, workers, now);
  enter_ns(0);
  std::string note;
  slab_peak = std::max(slab_peak, slab_objects(&note, false));
  // Only a TAKE between two audits passes entries over: the table of
  // subscribers that took starts afresh, and does not fill up in a long run.
  for (auto& k : sh->taken) k = 0;
  sh->taken_overflow = false;
  last_audit = std::move(now);
  audits++;
  sh->pause = false;
  return ok;
}

// --- The parent's liveness check of the listeners ---------------------------

// A listener's subscriber as the parent saw it.
struct Backlog {
  using Clock = std::chrono::steady_clock;
  // What it had been given (received + unreceived + dropped) each time the
  // parent saw more given than received or dropped, and when.
  std::deque<std::pair<Clock::time_point, uint64_t>> given;
  // Since when entries have waited for it while it received none (drops
  // retire entries too: a subscriber that sleeps on while new entries push
  // the old ones out receives nothing), and what it had received then.
  std::optional<Clock::time_point> starved_since;
  uint64_t received = 0;
  bool reported = false;
};
// (namespace, topic, subscriber id, pid)
std::map<std::tuple<int, int, uint32_t, int>, Backlog> backlogs;
uint64_t liveness_checks = 0;
Backlog::Clock::duration longest_wait{};

// Whatever a listener's subscriber is given, it receives or drops within
// kLivenessBound, and while entries wait for it, it receives one within
// kLivenessBound.  Listeners never pause: this holds through audits too.
bool check_liveness(int dev) {
  using std::chrono::duration_cast;
  using std::chrono::milliseconds;
  bool ok = true;
  const auto now = Backlog::Clock::now();
  decltype(backlogs) seen;
  std::vector<agnocast_subscriber_info> subs(2048);
  for (int ns = 0; ns < kNamespaces; ns++) {
    if (!enter_ns(ns)) continue;
    for (int t = 0; t < kNumTopics; t++) {
      agnocast_topic_info info{};
      std::strcpy(info.name, kTopics[t]);
      info.subscribers = uptr(subs.data());
      info.subscriber_capacity = static_cast<uint32_t>(subs.size());
      if (ioc(dev, AGNOCAST_IOC_TOPIC_INFO, &info)) continue;
      for (uint32_t i = 0; i < std::min<uint32_t>(info.subscriber_total, 2048); i++) {
        const auto& s = subs[i];
        const Shared::Listener* listener = nullptr;
        for (const auto& l : sh->listeners)
          if (l.pid == s.pid && l.ns == ns) listener = &l;
        if (!listener) continue;
        const auto key = std::make_tuple(ns, t, s.id, s.pid);
        Backlog& b = seen[key] = std::move(backlogs[key]);
        const uint64_t done = s.received + s.dropped, given = done + s.unreceived;
        while (!b.given.empty() && b.given.front().second <= done) b.given.pop_front();
        if (given > done && (b.given.empty() || b.given.back().second < given))
          b.given.emplace_back(now, given);
        if (!s.unreceived || s.received != b.received) b.starved_since.reset();
        if (s.unreceived && !b.starved_since) b.starved_since = now;
        b.received = s.received;
        liveness_checks++;
        const Backlog::Clock::duration none{};
        const auto unretired = b.given.empty() ? none : now - b.given.front().first;
        const auto starved = b.starved_since ? now - *b.starved_since : none;
        longest_wait = std::max({longest_wait, unretired, starved});
        if (std::max(unretired, starved) <= kLivenessBound || b.reported) continue;
        b.reported = true;
        ok = false;
        const bool starving = starved > kLivenessBound;
        std::printf(
            "fuzz: FAIL: liveness: %s subscriber %u of IPC namespace %d (listener pid %d, flags "
            "%u): for %lld ms %s (bound %lld ms); received %llu, unreceived %u, dropped %llu; "
            "its listener last woke %lld ms ago\n",
            kTopics[t], s.id, ns, s.pid, s.flags,
            static_cast<long long>(
                duration_cast<milliseconds>(starving ? starved : unretired).count()),
            starving ? "entries waited while it received none"
                     : "entries given to it were neither received nor dropped",
            static_cast<long long>(kLivenessBound.count()),
            static_cast<unsigned long long>(s.received), s.unreceived,
            static_cast<unsigned long long>(s.dropped),
            static_cast<long long>((monotonic_ns() - listener->last_wake) / 1000000));
        std::fflush(stdout);
      }
    }
  }
  enter_ns(0);
  backlogs = std::move(seen);
  return ok;
}

// --- The world around the workers --------------------------------------

// The second IPC namespace: a process that made it and waits.
pid_t make_second_namespace() {
  int p[2];
  if (pipe(p)) return -1;
  pid_t pid = fork();
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    char made = unshare(CLONE_NEWIPC) == 0;
    (void)!write(p[1], &made, 1);
    for (;;) pause();
  }
  close(p[1]);
  char made = 0;
  if (pid > 0 && (read(p[0], &made, 1) != 1 || !made)) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    pid = -1;
  }
  close(p[0]);
  return pid;
}

// The module's namespace states (its debugfs count), or -1.
long namespace_states() {
  struct stat st;
  if (stat("/sys/kernel/debug/agnocast", &st) != 0)
    mount("debugfs", "/sys/kernel/debug", "debugfs", 0, nullptr);
  std::ifstream in("/sys/kernel/debug/agnocast/namespaces");
  long n = -1;
  in >> n;
  return n;
}

// Objects in use in the module's entry cache, after a shrink (which flushes
// the per-CPU slabs, so the count is exact; without, their free objects count
// too); -1 when the cache is absent or merged with another one (whose objects
// would count too), said in *note.
const char kEntrySlab[] = "/sys/kernel/slab/agnocast_topic_entry";
long slab_objects(std::string* note, bool shrink) {
  struct stat st;
  if (lstat(kEntrySlab, &st)) {
    *note = "no agnocast_topic_entry in /sys/kernel/slab";
    return -1;
  }
  if (S_ISLNK(st.st_mode)) {
    char target[256] = {};
    (void)!readlink(kEntrySlab, target, sizeof(target) - 1);
    *note = std::string("agnocast_topic_entry is merged into ") + target;
    return -1;
  }
  if (shrink) std::ofstream(std::string(kEntrySlab) + "/shrink") << 1;
  std::ifstream in(std::string(kEntrySlab) + "/objects");
  long n = -1;
  in >> n;
  return n;
}

// The module's parameters (its quotas among them) and their values.
std::map<std::string, std::string> module_parameters() {
  std::map<std::string, std::string> out;
  const std::string dir = "/sys/module/agnocast/parameters";
  DIR* d = opendir(dir.c_str());
  if (!d) return out;
  while (dirent* e = readdir(d)) {
    if (e->d_name[0] == '.') continue;
    std::ifstream in(dir + "/" + e->d_name);
    std::getline(in, out[e->d_name]);
  }
  closedir(d);
  return out;
}

// None of them can change while the module is loaded (agnocastd's reload
// says so: "the loaded module keeps its value until it is reloaded"); not
// even root may open one for writing.  Should one become writable, the
// fuzzer has to change it while it runs: until then this fails.
bool parameters_fixed(const std::map<std::string, std::string>& at_start) {
  bool ok = true;
  for (const auto& [name, value] : at_start) {
    const std::string path = "/sys/module/agnocast/parameters/" + name;
    int fd = open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd >= 0 || errno != EACCES) {
      std::printf(
          "fuzz: FAIL: module parameter %s %s at run time (the fuzzer does not change "
          "it)\n",
          name.c_str(), fd >= 0 ? "is writable" : "cannot be judged");
      ok = false;
    }
    if (fd >= 0) close(fd);
  }
  if (module_parameters() != at_start) {
    std::printf("fuzz: FAIL: the module's parameters changed while it ran\n");
    ok = false;
  }
  return ok;
}

// Since the parameters cannot change under the workers, a third of the runs
// (by seed; --caps: every one) reload the module with small caps before
// anything opens it, so that the caps are hit in the storm: endpoints per
// process, entries held per subscriber, topics per namespace (each of the
// two namespaces has its own).
const char kSmallCaps[] =
    "max_endpoints_per_process=6 max_held_per_subscriber=4 max_topics_per_namespace=5";
bool reload_module(const char* params) {
  const char* path = std::getenv("AGNOCAST_MODULE");
  if (!path) return false;
  eventually(
      [] { return syscall(SYS_delete_module, "agnocast", O_NONBLOCK) == 0 || errno == ENOENT; });
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  bool loaded = syscall(SYS_finit_module, fd, params, 0) == 0;
  close(fd);
  // As the VM bed (and the shipped udev rule) does: group agnocast may use it.
  return loaded && eventually([] { return access(AGNOCAST_DEVICE_PATH, F_OK) == 0; }) &&
         chown(AGNOCAST_DEVICE_PATH, static_cast<uid_t>(-1), kAgnocastGroup) == 0;
}

// agnocastd beside the fuzzer, reloading configurations with other access
// policies (and some that do not parse) on SIGHUP while the workers run.
const char* const kDaemonConfigs[] = {
    R"({"log_level": "info", "sweep_interval_s": 1})",
    R"({"sweep_interval_s": 2, "access": {"default": "allow", "rules": [{"topics": "/x/**", )"
    R"("publish": ["*"], "subscribe": ["*"]}]}})",
    R"({"access": {"rules": [{"topics": "/q", "publish": ["group:990"]}, )"
    R"({"topics": "/a/*", "subscribe": ["user:0", "*"]}]}})",
    R"({"access": {"default": "allow", "rules": [{"topics": "/**", "publish": ["*"], )"
    R"("subscribe": ["group:990", "*"]}]}})",
    R"({"access": {"rules": [)",  // does not parse: the configuration in force stays
};
const char kDaemonConfig[] = "fuzz-agnocastd.json";
const char kDaemonLog[] = "fuzz-agnocastd.log";

struct Daemon {
  pid_t pid = -1;
  uint64_t sighups = 0;

  static void write_config(int i) {
    {
      std::ofstream out(std::string(kDaemonConfig) + ".new");
      out << kDaemonConfigs[i] << "\n";
    }
    std::rename((std::string(kDaemonConfig) + ".new").c_str(), kDaemonConfig);
  }

  void dump_log() const {
    std::ifstream in(kDaemonLog);
    for (std::string line; std::getline(in, line);) std::printf("  agnocastd| %s\n", line.c_str());
  }

  // false: not beside the fuzzer (policies then change by SET_POLICY only).
  bool start(bool* ok) {
    char exe[4096] = {};
    if (readlink("/proc/self/exe", exe, sizeof(exe) - 1) <= 0) return false;
    std::string path(exe);
    path = path.substr(0, path.rfind('/') + 1) + "agnocastd";
    if (access(path.c_str(), X_OK)) return false;
    write_config(0);
    pid = fork();
    if (pid == 0) {
      for (int fd : sh->ns_fd)
        if (fd >= 0) close(fd);
      close(shared_fd);
      int log = open(kDaemonLog, O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(log, 1);
      dup2(log, 2);
      execl(path.c_str(), "agnocastd", "--config", kDaemonConfig, static_cast<char*>(nullptr));
      _exit(127);
    }
    const std::string pid_field = "\"pid\":" + std::to_string(pid) + ",";
    bool ready = eventually(
        [&] {
          std::ifstream in("/run/agnocast/agnocastd.json");
          std::string text((std::istreambuf_iterator<char>(in)), {});
          return text.find(pid_field) != std::string::npos &&
                 text.find("\"running\":true") != std::string::npos;
        },
        30000);
    if (!ready) {
      std::printf("fuzz: FAIL: agnocastd did not become ready\n");
      dump_log();
      *ok = false;
    }
    return true;
  }

  bool alive() {
    if (pid <= 0) return true;
    int status;
    if (waitpid(pid, &status, WNOHANG) == 0) return true;
    std::printf("fuzz: FAIL: agnocastd died while the fuzzer ran (status 0x%x)\n", status);
    dump_log();
    pid = -1;
    return false;
  }

  void reload(std::mt19937_64& rng) {
    if (pid <= 0) return;
    write_config(static_cast<int>(rng() % std::size(kDaemonConfigs)));
    kill(pid, SIGHUP);
    sighups++;
  }

  // Stops it: it must exit 0, having acted on the SIGHUPs (some may
  // coalesce) and survived the files that do not parse.
  bool stop(uint64_t* reloads, uint64_t* refused) {
    if (pid <= 0) return true;
    kill(pid, SIGTERM);
    int status = -1;
    bool gone = eventually([&] { return waitpid(pid, &status, WNOHANG) == pid; }, 10000);
    if (!gone) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
    }
    pid = -1;
    std::ifstream in(kDaemonLog);
    for (std::string line; std::getline(in, line);) {
      if (line.find("configuration reloaded") != std::string::npos) ++*reloads;
      if (line.find("configuration not reloaded") != std::string::npos) ++*refused;
    }
    bool ok = true;
    if (!gone || !WIFEXITED(status) || WEXITSTATUS(status)) {
      std::printf("fuzz: FAIL: agnocastd did not exit 0 on SIGTERM (status 0x%x)\n", status);
      ok = false;
    }
    if (sighups && (*reloads + *refused == 0 || *reloads + *refused > sighups)) {
      std::printf("fuzz: FAIL: agnocastd acted on %llu of %llu SIGHUPs\n",
                  static_cast<unsigned long long>(*reloads + *refused),
                  static_cast<unsigned long long>(sighups));
      ok = false;
    }
    if (!ok) dump_log();
    return ok;
  }
};

void print_table() {
  std::printf("fuzz: %-20s %10s  errors\n", "command", "ok");
  for (int r = 0; r < kRows; r++) {
    std::printf("fuzz: %-20s %10llu ", kRowNames[r],
                static_cast<unsigned long long>(sh->count[r][0].load()));
    for (int e = 1; e < kErrnos; e++) {
      uint64_t n = sh->count[r][e];
      if (!n) continue;
      const char* name = strerrorname_np(e);
      if (name)
        std::printf(" %s:%llu", name, static_cast<unsigned long long>(n));
      else
        std::printf(" %d:%llu", e, static_cast<unsigned long long>(n));
    }
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  // A worker that exec'd: agnocast_fuzz_test --worker SLOT SEED SHARED_FD.
  if (argc == 5 && std::string(argv[1]) == "--worker") {
    shared_fd = std::atoi(argv[4]);
    sh = static_cast<Shared*>(
        mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED, shared_fd, 0));
    if (sh == MAP_FAILED) return 2;
    worker_process(std::atoi(argv[2]), std::strtoull(argv[3], nullptr, 10), true);
  }
  int seconds = -1, nprocs = 6;
  long long min_ops = -1;
  bool long_mode = std::getenv("AGNOCAST_FUZZ_LONG") != nullptr;
  int caps_arg = -1;  // --caps 1, --no-caps 0, else by seed
  int namespaces_arg = -1;
  uint64_t base_seed = 0;
  bool seeded = false;
  bool unguided = false;
  int positional = 0;
  for (int i = 1; i < argc; i++) {
    std::string a = argv[i];
    if (a == "--long") {
      long_mode = true;
    } else if (a == "--namespaces" || a == "--no-namespaces") {
      namespaces_arg = a == "--namespaces";
    } else if (a == "--caps" || a == "--no-caps") {
      caps_arg = a == "--caps";
    } else if (a == "--unguided") {
      unguided = true;
    } else if (a == "--ops" && i + 1 < argc) {
      min_ops = std::atoll(argv[++i]);
    } else if (a == "--seed" && i + 1 < argc) {
      base_seed = std::strtoull(argv[++i], nullptr, 0);
      seeded = true;
    } else if (positional == 0) {
      seconds = std::atoi(argv[i]), positional++;
    } else {
      nprocs = std::atoi(argv[i]), positional++;
    }
  }
  if (seconds < 0) seconds = long_mode ? 4 * 3600 : 30;
  if (min_ops < 0) min_ops = long_mode ? 1000000 : 0;
  nprocs = std::clamp(nprocs, 1, kMaxProcs);
  if (!seeded) base_seed = std::random_device{}() ^ (static_cast<uint64_t>(time(nullptr)) << 20);
  std::printf("fuzz: %d s and %lld operations at least, %d processes, seed %llu\n", seconds,
              min_ops, nprocs, static_cast<unsigned long long>(base_seed));
  std::fflush(stdout);

  shared_fd = memfd_create("agnocast-fuzz", 0);
  if (shared_fd < 0 || ftruncate(shared_fd, sizeof(Shared))) return 2;
  sh = static_cast<Shared*>(
      mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED, shared_fd, 0));
  sh->unguided = unguided;
  // kcov lives in debugfs (the debug kernel has it): mounted if need be.
  if (access("/sys/kernel/debug/kcov", F_OK))
    mount("debugfs", "/sys/kernel/debug", "debugfs", 0, nullptr);
  const bool kcov = KcovTrace().available();
  std::printf("fuzz: kcov: %s\n", !kcov      ? "not in this kernel: unguided, no edges counted"
                                  : unguided ? "edges counted, unguided (--unguided)"
                                             : "edges counted, guiding the steps");
  std::fflush(stdout);
  std::mt19937_64 rng(base_seed);
  bool ok = true;
  // Workers in the second namespace find wrong messages there (tests/README.md,
  // "Fuzzing the module"): on in the long mode, off in the suite's short run
  // until that is fixed; threads visit the second namespace either way.
  const bool namespaces = namespaces_arg != 0;
  bool caps =
      caps_arg == 1 || (caps_arg < 0 && base_seed % 3 == 0 && std::getenv("AGNOCAST_MODULE"));
  if (caps) {
    caps = reload_module(kSmallCaps);
    std::printf(
        "fuzz: %s: %s\n",
        caps ? "the module reloaded with small caps" : "FAIL: could not reload $AGNOCAST_MODULE",
        kSmallCaps);
    ok &= caps;
  }

  // The second IPC namespace; descriptors of both, inherited by every
  // worker (across exec too).
  const pid_t holder = make_second_namespace();
  sh->ns_fd[0] = open("/proc/self/ns/ipc", O_RDONLY);
  sh->ns_fd[1] = -1;
  if (holder > 0)
    sh->ns_fd[1] = open(("/proc/" + std::to_string(holder) + "/ns/ipc").c_str(), O_RDONLY);
  if (sh->ns_fd[0] < 0 || sh->ns_fd[1] < 0) {
    std::printf("fuzz: FAIL: no second IPC namespace (%s)\n", strerrorname_np(errno));
    ok = false;
  }
  int dev = open_device();
  // What must be as before once every worker is gone.
  const long states_before = namespace_states();
  std::string slab_note;
  const long slab_before = slab_objects(&slab_note);
  const auto parameters = module_parameters();
  Daemon daemon;
  const bool with_daemon = daemon.start(&ok);
  std::printf("fuzz: %s\n", with_daemon ? "agnocastd runs, reloading its configuration on SIGHUP"
                                        : "no agnocastd beside the fuzzer");
  std::fflush(stdout);

  std::vector<pid_t> workers(nprocs);
  uint64_t spawned = 0;
  auto spawn = [&](int i) {
    uint64_t seed = base_seed + spawned++;
    // With --namespaces, a third of the slots live in the second namespace.
    sh->slots[i].ns = namespaces && i % 3 == 2 ? 1 : 0;
    sh->slots[i].paused = 0;
    for (auto& p : sh->slots[i].published) p = 0;
    sh->slots[i].pid = 0;
    pid_t pid = fork();
    if (pid == 0) worker_process(i, seed, false);
    sh->slots[i].pid = pid;
    workers[i] = pid;
  };
  for (int i = 0; i < nprocs; i++) spawn(i);
  // Listeners: one at home, one in the second namespace (with --namespaces).
  std::vector<pid_t> listeners(kListeners);
  uint64_t listener_spawns = 0;
  auto spawn_listener = [&](int k) {
    auto& l = sh->listeners[k];
    l.ns = namespaces && k % 2 ? 1 : 0;
    l.last_wake = monotonic_ns();
    const uint64_t seed = (base_seed + listener_spawns++) * 0x9E3779B97F4A7C15ull;
    pid_t pid = fork();
    if (pid == 0) Listener(k, seed).run(l.ns);
    l.pid = pid;
    listeners[k] = pid;
  };
  // A dead listener's queues go, as agnocastd removes a dead subscriber's
  // queues in its own namespace.
  auto bury_listener = [&](int k) {
    auto& l = sh->listeners[k];
    std::vector<uint64_t> keys;
    for (auto& q : l.queues)
      if (uint64_t key = q.exchange(0)) keys.push_back(key);
    if (!enter_ns(l.ns)) return;
    for (uint64_t key : keys) {
      const int topic = static_cast<int>((key >> 32) - 1);
      if (!listener_queue(l.ns, topic, static_cast<uint32_t>(key)))
        mq_unlink(queue_name(topic, static_cast<uint32_t>(key)).c_str());
    }
    enter_ns(0);
  };
  for (int k = 0; k < kListeners; k++) spawn_listener(k);

  const auto start = std::chrono::steady_clock::now();
  const auto deadline = start + std::chrono::seconds(seconds);
  auto next_audit = start + std::chrono::seconds(1);
  auto next_reload = start + std::chrono::seconds(2);
  auto next_report = start + std::chrono::seconds(600);
  // kcov's edges after 1, 2, 4, ... s, then every 10 minutes: whether a long
  // run still finds code.
  auto edges_interval = std::chrono::seconds(1);
  auto next_edges_report = start + edges_interval;
  while (std::chrono::steady_clock::now() < deadline ||
         sh->ops.load() < static_cast<uint64_t>(min_ops)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50 + rng() % 200));
    auto now = std::chrono::steady_clock::now();
    if (now >= next_audit) {
      ok &= audit(dev, workers);
      ok &= daemon.alive();
      next_audit = now + std::chrono::milliseconds(500 + rng() % 1000);
    }
    if (now >= next_reload) {
      daemon.reload(rng);
      ok &= parameters_fixed(parameters);
      next_reload = now + std::chrono::milliseconds(1500 + rng() % 2000);
    }
    // Processes killed by a fault come back at once (a worker that ended on
    // its own waits for the parent's pick).
    for (int k = 0; k < kListeners; k++) {
      if (waitpid(listeners[k], nullptr, WNOHANG) != listeners[k]) continue;
      bury_listener(k);
      spawn_listener(k);
    }
    for (int i = 0; i < nprocs; i++) {
      siginfo_t info{};
      if (waitid(P_PID, static_cast<id_t>(workers[i]), &info, WEXITED | WNOHANG | WNOWAIT) ||
          info.si_pid != workers[i] || info.si_code != CLD_KILLED)
        continue;
      waitpid(workers[i], nullptr, 0);
      settle_slot(i);
      spawn(i);
    }
    ok &= check_liveness(dev);
    if (now >= next_report) {
      std::printf("fuzz: %llu operations after %lld s\n",
                  static_cast<unsigned long long>(sh->ops.load()),
                  static_cast<long long>(
                      std::chrono::duration_cast<std::chrono::seconds>(now - start).count()));
      std::fflush(stdout);
      next_report = now + std::chrono::seconds(600);
    }
    if (kcov && now >= next_edges_report) {
      std::printf("fuzz: kcov: %llu edges after %lld s and %llu operations, %llu inputs kept\n",
                  static_cast<unsigned long long>(sh->guide.edges.load()),
                  static_cast<long long>(
                      std::chrono::duration_cast<std::chrono::seconds>(now - start).count()),
                  static_cast<unsigned long long>(sh->ops.load()),
                  static_cast<unsigned long long>(sh->guide.inputs.load()));
      std::fflush(stdout);
      edges_interval =
          std::min<std::chrono::seconds>(edges_interval * 2, std::chrono::seconds(600));
      next_edges_report = now + edges_interval;
    }
    if (rng() % 3) continue;
    int i = static_cast<int>(rng() % nprocs);
    int status;
    if (waitpid(workers[i], &status, WNOHANG) == 0) {
      kill(workers[i], SIGKILL);
      waitpid(workers[i], &status, 0);
    }
    settle_slot(i);
    spawn(i);
  }
  for (pid_t pid : workers) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
  for (pid_t pid : listeners) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
  auto elapsed = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::steady_clock::now() - start);

  uint64_t reloads = 0, refused_reloads = 0;
  ok &= daemon.stop(&reloads, &refused_reloads);

  // Every worker is gone: so must be every registration and every topic, in
  // both namespaces.
  bool clean = true;
  for (int ns = 0; ns < kNamespaces; ns++) {
    if (!enter_ns(ns)) continue;
    bool gone = eventually([&] {
      agnocast_list_topics lt{0, 0, 0, 0, 0};
      return list_processes(dev).empty() && ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt) == 0 &&
             lt.total == 0;
    });
    if (!gone) {
      std::printf("fuzz: FAIL: state left over in IPC namespace %d after every worker exited\n",
                  ns);
      for (const auto& p : list_processes(dev)) std::printf("  left: pid %d\n", p.pid);
    }
    clean &= gone;
  }
  enter_ns(0);
  size_t records = drain_exit_records(dev).size();
  // The second namespace ends: its state must go with it (collected at the
  // next open), and the module's entries must all be back in the cache.
  if (holder > 0) {
    kill(holder, SIGKILL);
    waitpid(holder, nullptr, 0);
  }
  for (int& fd : sh->ns_fd)
    if (fd >= 0) close(fd), fd = -1;
  long states_after = states_before;
  if (states_before >= 0 && !eventually([&] {
        close(open_device());
        return (states_after = namespace_states()) == states_before;
      })) {
    std::printf("fuzz: FAIL: %ld namespace states after the run, %ld before\n", states_after,
                states_before);
    ok = false;
  }
  long slab_after = slab_before;
  if (slab_before >= 0 &&
      !eventually([&] { return (slab_after = slab_objects(&slab_note)) <= slab_before; })) {
    std::printf("fuzz: FAIL: %ld agnocast_topic_entry objects in use after the run, %ld before\n",
                slab_after, slab_before);
    ok = false;
  }
  ok &= parameters_fixed(parameters);
  print_table();
  const double secs = static_cast<double>(elapsed.count()) / 1000;
  std::printf(
      "fuzz: %llu operations in %.1f s (%.0f per second), %llu worker processes, %zu exit "
      "records\n"
      "fuzz: messages checked: %llu on receipt, %llu again at release, %llu unreadable\n"
      "fuzz: %llu audits (%llu subscriber counts checked, %llu audits skipped)\n"
      "fuzz: %llu forks with the device open, %llu device files replaced in use, %llu workers "
      "as a member of group agnocast, %llu as a non-member, %llu execs\n",
      static_cast<unsigned long long>(sh->ops.load()), secs,
      static_cast<double>(sh->ops.load()) / std::max(secs, 0.001),
      static_cast<unsigned long long>(spawned), records,
      static_cast<unsigned long long>(sh->verified.load()),
      static_cast<unsigned long long>(sh->rechecked.load()),
      static_cast<unsigned long long>(sh->unverifiable.load()),
      static_cast<unsigned long long>(audits), static_cast<unsigned long long>(audit_checks),
      static_cast<unsigned long long>(audits_skipped),
      static_cast<unsigned long long>(sh->forks.load()),
      static_cast<unsigned long long>(sh->device_swaps.load()),
      static_cast<unsigned long long>(sh->members.load()),
      static_cast<unsigned long long>(sh->non_members.load()),
      static_cast<unsigned long long>(sh->execs.load()));
  std::printf(
      "fuzz: second IPC namespace: %llu workers, %llu visits from the other one (%llu commands "
      "refused there), %llu registrations checked for their namespace\n",
      static_cast<unsigned long long>(sh->ns_workers.load()),
      static_cast<unsigned long long>(sh->ns_visits.load()),
      static_cast<unsigned long long>(sh->ns_probes.load()),
      static_cast<unsigned long long>(isolation_checks));
  std::printf(
      "fuzz: liveness: %llu listener processes, %llu entries received on %llu wake-ups by a "
      "queue and %llu by the wake eventfd; %llu subscriber states checked, the longest wait "
      "seen %lld ms (bound %lld ms)\n",
      static_cast<unsigned long long>(listener_spawns),
      static_cast<unsigned long long>(sh->listener_entries.load()),
      static_cast<unsigned long long>(sh->queue_wakes.load()),
      static_cast<unsigned long long>(sh->eventfd_wakes.load()),
      static_cast<unsigned long long>(liveness_checks),
      static_cast<long long>(
          std::chrono::duration_cast<std::chrono::milliseconds>(longest_wait).count()),
      static_cast<long long>(kLivenessBound.count()));
  std::printf(
      "fuzz: notifications to listeners: %llu sent, %llu left unsent and reported, %llu left "
      "unsent silently, %llu reported after a failed mq_open or mq_send; %llu queues unlinked "
      "under their listener, %llu others made under a listener's queue name\n",
      static_cast<unsigned long long>(sh->sent.load()),
      static_cast<unsigned long long>(sh->unsent_reported.load()),
      static_cast<unsigned long long>(sh->unsent_silent.load()),
      static_cast<unsigned long long>(sh->send_failed.load()),
      static_cast<unsigned long long>(sh->unlinked.load()),
      static_cast<unsigned long long>(sh->replaced.load()));
  std::printf("fuzz: processes killed on the message path:");
  for (int k = 0; k < kKillPoints; k++)
    std::printf("%s %s %llu", k ? "," : "", kKillPointNames[k],
                static_cast<unsigned long long>(sh->kills[k].load()));
  std::printf("\n");
  std::printf("fuzz: agnocastd: %llu SIGHUPs, %llu reloads applied, %llu refused\n",
              static_cast<unsigned long long>(daemon.sighups),
              static_cast<unsigned long long>(reloads),
              static_cast<unsigned long long>(refused_reloads));
  std::printf("fuzz: namespace states %ld before, %ld after; agnocast_topic_entry objects %s\n",
              states_before, states_after,
              slab_before >= 0
                  ? (std::to_string(slab_before) + " before, " + std::to_string(slab_peak) +
                     " at most during, " + std::to_string(slab_after) + " after")
                        .c_str()
                  : ("not counted: " + slab_note).c_str());
  if (caps) {
    // Each cap refuses with its own errno (the UAPI header's list).
    uint64_t endpoints = sh->count[kAddPublisher][EMFILE] + sh->count[kAddSubscriber][EMFILE];
    uint64_t topics = sh->count[kAddPublisher][ENFILE] + sh->count[kAddSubscriber][ENFILE];
    uint64_t held = sh->count[kReceive][EDQUOT] + sh->count[kTake][EDQUOT];
    std::printf(
        "fuzz: caps hit: endpoints per process %llu, topics per namespace %llu, held "
        "entries %llu\n",
        static_cast<unsigned long long>(endpoints), static_cast<unsigned long long>(topics),
        static_cast<unsigned long long>(held));
    if (!endpoints && !topics && !held) {
      std::printf("fuzz: FAIL: the module has small caps, yet no cap was hit\n");
      ok = false;
    }
  }
  if (namespaces && nprocs >= 3 && !sh->ns_workers) {
    std::printf("fuzz: FAIL: no worker ran in the second IPC namespace\n");
    ok = false;
  }
  if (!liveness_checks || !sh->eventfd_wakes) {
    std::printf("fuzz: FAIL: %s\n", !liveness_checks
                                        ? "no listener's subscriber was checked for liveness"
                                        : "no wake eventfd ever woke a listener");
    ok = false;
  }
  for (int r = 0; r < kRows; r++) {
    if (r == kUnknown || sh->count[r][0]) continue;
    std::printf("fuzz: FAIL: %s never succeeded\n", kRowNames[r]);
    ok = false;
  }
  if (kcov) {
    std::printf("fuzz: kcov: %llu edges of the module in %llu operations, %llu inputs kept%s\n",
                static_cast<unsigned long long>(sh->guide.edges.load()),
                static_cast<unsigned long long>(sh->ops.load()),
                static_cast<unsigned long long>(sh->guide.inputs.load()),
                unguided ? " (unguided)" : "");
    if (!sh->guide.edges) {
      std::printf(
          "fuzz: FAIL: kcov counted no edge: is the module built with KCOV_INSTRUMENT "
          "(AGNOCAST_COVERAGE=1)?\n");
      ok = false;
    }
  }
  if (sh->failures) {
    std::printf("fuzz: FAIL: %llu wrong messages (see above)\n",
                static_cast<unsigned long long>(sh->failures.load()));
    ok = false;
  }
  if (!clean) ok = false;
  std::printf(
      "fuzz: %s (seed %llu; replay: agnocast_fuzz_test %d %d --ops %lld --seed %llu%s%s%s)\n",
      ok ? "PASS" : "FAIL", static_cast<unsigned long long>(base_seed), seconds, nprocs, min_ops,
      static_cast<unsigned long long>(base_seed), caps ? " --caps" : " --no-caps",
      namespaces ? " --namespaces" : " --no-namespaces", unguided ? " --unguided" : "");
  return ok ? 0 : 1;
}
