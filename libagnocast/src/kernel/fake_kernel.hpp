// An in-memory Kernel for native tests: topics, publisher windows, each
// subscriber's unreceived and held entries, wake ids and reclaim, following
// the UAPI header's contract for one process. It grants no pools: every
// message lives in the test runtime's own region.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "kernel/kernel.hpp"

namespace agnocast::detail {

class FakeKernel final : public Kernel {
 public:
  FakeKernel();
  ~FakeKernel() override;
  FakeKernel(const FakeKernel&) = delete;
  FakeKernel& operator=(const FakeKernel&) = delete;

  // How often each call was made, for tests of the library's loops.
  struct Calls {
    int publish = 0;
    int receive = 0;
    int take = 0;
    int release = 0;
    // Entries released: by release() and by receive()'s release lists.
    int released_entries = 0;
    int reclaim = 0;
    int shed = 0;
  };

  EndpointId add_publisher(const EndpointRequest& request) override;
  EndpointId add_subscriber(const EndpointRequest& request) override;
  void remove_publisher(EndpointId endpoint) override;
  void remove_subscriber(EndpointId endpoint) override;
  PublishResult publish(EndpointId publisher, std::uint64_t addr, std::uint64_t bytes,
                        std::span<std::uint32_t> wake_ids, std::span<std::uint64_t> reclaim,
                        const ServiceRoute& route) override;
  void notify_failed(EndpointId publisher, std::uint32_t subscriber_id) noexcept override;
  // The caller process's wake eventfd, made on first use.
  int wake_fd() const override;
  ReclaimResult reclaim(std::span<std::uint64_t> reclaim) override;
  std::uint32_t shed() override;
  ReceiveResult receive(EndpointId subscriber, std::span<ReceivedEntry> entries,
                        std::span<PoolGrant> pools,
                        std::span<const std::uint64_t> release_ids) override;
  TakeResult take(EndpointId subscriber) override;
  void release(EndpointId subscriber, std::span<const std::uint64_t> entry_ids) override;
  bool topic_info(const std::string& topic, TopicInfo& info) override;
  void close() noexcept override {}

  Calls calls() const;
  // Entries not reclaimed yet, whoever references them.
  std::size_t live_entries() const;
  // The process the next calls come from, to act as several processes.
  void set_caller_pid(pid_t pid);
  // From now on release() fails with err (0: succeeds again).
  void fail_releases(int err);
  // The process dies, as the module's teardown sees it: the promises it made
  // break, then its endpoints go.
  void end_process(pid_t pid);
  // What the module's watchdog does on its own: signals the wake eventfd of
  // a subscriber that has not looked within the watchdog period
  // (AGNOCAST_WAKE_WATCHDOG_MS) of its listing, once per listing, without
  // listing it again. Every call runs it too.
  void run_watchdog();
  static constexpr std::chrono::milliseconds watchdog_period{50};

 private:
  struct Entry {
    std::uint64_t addr = 0;
    std::uint32_t topic_handle = 0;
    std::uint32_t publisher_id = 0;
    pid_t pid = 0;
    bool in_window = true;
    std::uint32_t unreceived_by = 0;
    std::uint32_t held_by = 0;
  };
  struct Publisher {
    std::string node;
    pid_t pid = 0;
    std::uint32_t depth = 1;
    bool transient_local = false;
    std::deque<std::uint64_t> window;
    std::uint64_t published = 0;
    std::uint64_t published_bytes = 0;
  };
  struct Subscriber {
    std::string node;
    pid_t pid = 0;
    std::uint32_t depth = 1;
    bool transient_local = false;
    bool polling = false;
    bool ignore_local = false;
    bool wake_once = false;
    // Listed in a wake set since its last receive (a wake_once one is listed
    // again only when false), when first, and by which process.
    bool notified = false;
    std::chrono::steady_clock::time_point notified_at;
    pid_t notifier = 0;
    bool watchdog_fired = false;  // signalled for this listing already
    std::deque<std::uint64_t> unreceived;
    std::multiset<std::uint64_t> held;
    std::uint64_t received = 0;
    std::uint64_t dropped = 0;
  };
  struct Topic {
    std::string name;
    std::string type_name;
    std::uint64_t type_hash = 0;
    std::map<std::uint32_t, Publisher> publishers;
    std::map<std::uint32_t, Subscriber> subscribers;
  };

  Topic& topic_of(EndpointId endpoint);
  // The handle of the request's topic, created when new; checks the type.
  std::uint32_t join(const EndpointRequest& request);
  Subscriber& subscriber_of(EndpointId endpoint);
  // The module's wake rules (kernel_module/agnocast_wake.c), mutex_ held.
  void promise(Subscriber& subscriber);
  void break_promise(Subscriber& subscriber);
  void signal_wake(pid_t pid);
  void break_overdue_promises();
  void remove_subscriber_locked(Topic& topic, std::uint32_t id);
  void remove_publisher_locked(Topic& topic, std::uint32_t id);
  // Drops one reference kind of an entry; an unreferenced entry becomes reclaimable.
  void settle(std::uint64_t entry_id);
  void drop_unreceived(Subscriber& subscriber, std::uint64_t entry_id);
  // Drops held entries, all or none, as RELEASE does; call names the failing call.
  void release_held(const char* call, Subscriber& subscriber,
                    std::span<const std::uint64_t> entry_ids);

  mutable std::mutex mutex_;
  pid_t caller_pid_;
  std::uint32_t next_handle_ = 1;
  std::uint32_t next_id_ = 1;
  std::uint64_t next_entry_id_ = 1;
  std::map<std::uint32_t, Topic> topics_;  // by handle
  std::map<std::uint64_t, Entry> entries_;
  std::map<pid_t, std::deque<std::uint64_t>> reclaimable_;  // addresses per owning process
  Calls calls_;
  int release_error_ = 0;
  mutable std::map<pid_t, int> wake_fds_;
};

}  // namespace agnocast::detail
