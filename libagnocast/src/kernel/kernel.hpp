// What the library asks of the kernel module for its publishers and
// subscribers, as one small interface: the device (device.hpp) implements it
// with ioctls, FakeKernel (fake_kernel.hpp) in memory for native tests of the
// receive/drain loop, ENOBUFS growth and executor re-arm.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/inspect.hpp"
#include "endpoints/endpoint_request.hpp"

namespace agnocast::detail {

struct EndpointId {
  std::uint32_t topic_handle = 0;
  std::uint32_t id = 0;
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

// Errors are thrown as DeviceError carrying the errno the module documents
// (ENOBUFS from publish() when wake_ids is too small, EDQUOT from receive()
// and take() when the subscriber holds too many entries).
class Kernel {
 public:
  virtual ~Kernel() = default;

  // The most entries and pool grants one receive() returns; larger spans are not filled further.
  // The module's batch: a receive of this many entries allocates nothing in the kernel.
  static constexpr std::size_t receive_entries_max = 8;
  static constexpr std::size_t receive_pools_max = 8;
  // The most ids one release(), or the release list of one receive(), names.
  static constexpr std::size_t release_max = 256;

  virtual EndpointId add_publisher(const EndpointRequest& request) = 0;
  virtual EndpointId add_subscriber(const EndpointRequest& request) = 0;
  virtual void remove_publisher(EndpointId endpoint) = 0;
  virtual void remove_subscriber(EndpointId endpoint) = 0;

  // wake_ids receives the ids of callback subscribers to notify, reclaim the
  // addresses of this process's messages no one references any more. A
  // service route's refusal is ENXIO (to_subscriber is gone), EAGAIN or EPIPE.
  virtual PublishResult publish(EndpointId publisher, std::uint64_t addr, std::uint64_t bytes,
                                std::span<std::uint32_t> wake_ids, std::span<std::uint64_t> reclaim,
                                const ServiceRoute& route) = 0;
  // The publisher could not send the notification publish() listed
  // subscriber_id for: the kernel wakes the subscriber's process through its
  // wake_fd() and lists it again at the next publish(). Never throws.
  virtual void notify_failed(EndpointId publisher, std::uint32_t subscriber_id) noexcept = 0;
  // Readable (an eventfd) when a notification to one of this process's
  // callback subscribers may have been lost: each of them should then
  // receive (OwnedQueue::wake_all()). -1 when there is none.
  virtual int wake_fd() const = 0;
  virtual ReclaimResult reclaim(std::span<std::uint64_t> reclaim) = 0;
  // Drops entries of this process's pool kept only for slow subscribers beyond
  // the publisher's depth; returns how many. Reclaim afterwards.
  virtual std::uint32_t shed() = 0;

  // Callback subscribers: drops the held entries release_ids (all or none, at
  // most release_max), then receives the oldest unreceived entries, now held
  // until released; an error releases and receives nothing.
  virtual ReceiveResult receive(EndpointId subscriber, std::span<ReceivedEntry> entries,
                                std::span<PoolGrant> pools,
                                std::span<const std::uint64_t> release_ids) = 0;
  // Polling subscribers: the newest unreceived entry, held until release().
  virtual TakeResult take(EndpointId subscriber) = 0;
  // Drops held entries, all or none (1..release_max ids).
  virtual void release(EndpointId subscriber, std::span<const std::uint64_t> entry_ids) = 0;

  // The topic's endpoints and counters; false when no endpoint uses it.
  virtual bool topic_info(const std::string& topic, TopicInfo& info) = 0;

  // Forgets the connection without undoing anything: a fork child's copy of
  // the parent's. Every other call fails afterwards.
  virtual void close() noexcept = 0;
};

}  // namespace agnocast::detail
