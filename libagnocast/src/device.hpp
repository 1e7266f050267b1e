// C++ wrapper over /dev/agnocast: one member per ioctl, errno turned into typed
// exceptions. The only part of the library that knows the UAPI structures.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "agnocast/access_policy.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/supervise.hpp"
#include "agnocast/version.hpp"

namespace agnocast::detail {

inline constexpr std::uint32_t depth_max = 1024;

struct PoolSlot {
  pid_t pid = 0;
  std::uint64_t addr = 0;
  std::uint64_t size = 0;
};

struct EndpointId {
  std::uint32_t topic_handle = 0;
  std::uint32_t id = 0;
};

struct EndpointRequest {
  std::string topic;
  std::string node;
  std::uint32_t depth = 1;
  bool transient_local = false;
  bool polling = false;
  // The message type: the topic's must be the same (TypeMismatch otherwise).
  std::string type_name;
  std::uint64_t type_hash = 0;
  std::span<const std::uint8_t> schema;  // kept by the kernel for tools; may be empty
};

struct PublishResult {
  std::uint64_t entry_id = 0;
  std::uint32_t wake_count = 0;
  std::uint32_t reclaim_count = 0;
  std::uint32_t reclaim_pending = 0;
};

struct ReclaimResult {
  std::uint32_t reclaim_count = 0;
  std::uint32_t reclaim_pending = 0;
};

struct ReceivedEntry {
  std::uint64_t entry_id = 0;
  std::uint64_t addr = 0;
  std::uint32_t publisher_id = 0;
};

// A read-only descriptor of a publisher's pool, owned by the receiver.
struct PoolGrant {
  std::uint64_t addr = 0;
  std::uint64_t size = 0;
  int fd = -1;
  pid_t pid = 0;
};

struct ReceiveResult {
  std::uint32_t entry_count = 0;
  std::uint32_t pool_count = 0;
  std::uint32_t remaining = 0;
};

struct TakeResult {
  bool has_entry = false;
  ReceivedEntry entry;
  bool has_pool = false;
  PoolGrant pool;
};

// Seals a pool memfd the way the module requires before it attaches it: after
// this the mapping made before is the only way to write the pool.
void seal_pool(int memfd);

class Device {
 public:
  // Opens /dev/agnocast O_CLOEXEC; read-write when permitted, else read-only
  // (enough for introspection). Throws ModuleNotLoaded when it is missing.
  static Device open(bool nonblocking = false);

  explicit Device(int fd) : fd_(fd) {}
  Device(Device&& other) noexcept;
  Device& operator=(Device&& other) noexcept;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  ~Device();

  int fd() const { return fd_; }
  // Closes the descriptor (fork child reset); the object becomes empty.
  void close();
  // Gives up ownership of the descriptor without closing it.
  int release() { return std::exchange(fd_, -1); }

  Version get_version() const;
  // pool_fd -1 reserves a slot; a memfd of the slot's size attaches it.
  PoolSlot register_process(int pool_fd) const;
  void unregister_process() const;

  EndpointId add_publisher(const EndpointRequest& request) const;
  EndpointId add_subscriber(const EndpointRequest& request) const;
  void remove_publisher(EndpointId endpoint) const;
  void remove_subscriber(EndpointId endpoint) const;

  PublishResult publish(EndpointId publisher, std::uint64_t addr, std::uint64_t bytes,
                        std::span<std::uint32_t> wake_ids, std::span<std::uint64_t> reclaim) const;
  ReclaimResult reclaim(std::span<std::uint64_t> reclaim) const;
  // The most entries and pool grants one receive() returns; larger spans are not filled further.
  static constexpr std::size_t receive_entries_max = 32;
  static constexpr std::size_t receive_pools_max = 8;
  // Drops the held entries release_ids first, in the same call (at most
  // AGNOCAST_RELEASE_MAX; all or none).
  ReceiveResult receive(EndpointId subscriber, std::span<ReceivedEntry> entries,
                        std::span<PoolGrant> pools,
                        std::span<const std::uint64_t> release_ids = {}) const;
  TakeResult take(EndpointId subscriber) const;
  // Drops held entries, all or none (1..AGNOCAST_RELEASE_MAX ids).
  void release(EndpointId subscriber, std::span<const std::uint64_t> entry_ids) const;
  // Drops entries of this process's pool kept only for slow subscribers beyond
  // the publisher's depth; returns how many. Reclaim afterwards.
  std::uint32_t shed() const;

  // The IPC namespace's topic access policy; nullopt when none is in force.
  std::optional<AccessPolicy> get_policy() const;
  // Needs CAP_SYS_ADMIN; nullopt removes the policy.
  void set_policy(const std::optional<AccessPolicy>& policy) const;

  std::vector<TopicSummary> list_topics() const;
  // The schema a topic's endpoints registered; nullopt when it has none or
  // no such topic has an endpoint.
  std::optional<std::vector<std::uint8_t>> topic_schema(const std::string& topic) const;
  // Returns false when no topic of that name has an endpoint.
  bool topic_info(const std::string& topic, TopicInfo& info) const;
  std::vector<ProcessInfo> list_processes() const;

  // Whole exit records waiting now (device opened non-blocking); empty if none.
  std::vector<ExitRecord> read_exit_records() const;

 private:
  int fd_ = -1;
};

}  // namespace agnocast::detail
