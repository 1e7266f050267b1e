// C++ wrapper over /dev/agnocast: one member per ioctl, errno turned into typed
// exceptions. The only part of the library that knows the UAPI structures; the
// real Kernel behind the library's publishers and subscribers.
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
#include "kernel/kernel.hpp"

namespace agnocast::detail {

struct PoolSlot {
  pid_t pid = 0;
  std::uint64_t addr = 0;
  std::uint64_t size = 0;
};

// Seals a pool memfd the way the module requires before it attaches it: after
// this the mapping made before is the only way to write the pool.
void seal_pool(int memfd);

class Device final : public Kernel {
 public:
  // Opens /dev/agnocast O_CLOEXEC; read-write when permitted, else read-only
  // (enough for introspection). Throws ModuleNotLoaded when it is missing.
  static Device open(bool nonblocking = false);

  explicit Device(int fd) : fd_(fd) {}
  Device(Device&& other) noexcept;
  Device& operator=(Device&& other) noexcept;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  ~Device() override;

  int fd() const { return fd_; }
  // Closes the descriptor (fork child reset); the object becomes empty.
  void close() noexcept override;
  // Gives up ownership of the descriptor without closing it.
  int release() { return std::exchange(fd_, -1); }

  Version get_version() const;
  // pool_fd -1 reserves a slot, and gives the module the wake eventfd,
  // created here; a memfd of the slot's size attaches it.
  PoolSlot register_process(int pool_fd);
  void unregister_process() const;

  EndpointId add_publisher(const EndpointRequest& request) override;
  EndpointId add_subscriber(const EndpointRequest& request) override;
  void remove_publisher(EndpointId endpoint) override;
  void remove_subscriber(EndpointId endpoint) override;
  PublishResult publish(EndpointId publisher, std::uint64_t addr, std::uint64_t bytes,
                        std::span<std::uint32_t> wake_ids, std::span<std::uint64_t> reclaim,
                        const ServiceRoute& route) override;
  void notify_failed(EndpointId publisher, std::uint32_t subscriber_id) noexcept override;
  int wake_fd() const override { return wake_fd_; }
  ReclaimResult reclaim(std::span<std::uint64_t> reclaim) override;
  std::uint32_t shed() override;
  ReceiveResult receive(EndpointId subscriber, std::span<ReceivedEntry> entries,
                        std::span<PoolGrant> pools,
                        std::span<const std::uint64_t> release_ids) override;
  TakeResult take(EndpointId subscriber) override;
  void release(EndpointId subscriber, std::span<const std::uint64_t> entry_ids) override;

  // The IPC namespace's topic access policy; nullopt when none is in force.
  std::optional<AccessPolicy> get_policy() const;
  // Needs CAP_SYS_ADMIN; nullopt removes the policy.
  void set_policy(const std::optional<AccessPolicy>& policy) const;

  std::vector<TopicSummary> list_topics() const;
  // The schema a topic's endpoints registered; nullopt when it has none or
  // no such topic has an endpoint.
  std::optional<std::vector<std::uint8_t>> topic_schema(const std::string& topic) const;
  // Returns false when no topic of that name has an endpoint.
  bool topic_info(const std::string& topic, TopicInfo& info) override;
  std::vector<ProcessInfo> list_processes() const;

  // Whole exit records waiting now (device opened non-blocking); empty if none.
  std::vector<ExitRecord> read_exit_records() const;

 private:
  int fd_ = -1;
  int wake_fd_ = -1;
};

}  // namespace agnocast::detail
