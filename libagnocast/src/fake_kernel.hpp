// An in-memory Kernel for native tests: topics, publisher windows, each
// subscriber's unreceived and held entries, wake ids and reclaim, following
// the UAPI header's contract for one process. It grants no pools: every
// message lives in the test runtime's own region.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "kernel.hpp"

namespace agnocast::detail {

class FakeKernel final : public Kernel {
 public:
  FakeKernel();

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
                        std::span<std::uint32_t> wake_ids,
                        std::span<std::uint64_t> reclaim) override;
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

 private:
  struct Entry {
    std::uint64_t addr = 0;
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
    bool notified = false;  // wake_once: listed in a wake set since its last receive
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
};

}  // namespace agnocast::detail
