// The publish → callback-start delays of this process's callback
// subscriptions, kept where agnocast-cli topic delay can read them without a
// tracing session: a file /dev/shm/agnocast_delays.<pid>, made on the first
// callback subscription, readable by everyone, written only by this process,
// removed at its exit (agnocastd removes those of processes that crashed).
// Each subscription has a slot: its topic and subscriber id, how many delays
// it recorded, and the newest of them in a ring.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace agnocast::detail {

inline constexpr char delay_file_prefix[] = "/dev/shm/agnocast_delays.";

// The file's layout; both sides are this library, of the same version.
struct DelayFileHeader {
  char magic[8];  // "agndelay"
  std::uint32_t version;
  std::uint32_t slot_count;
  std::uint32_t ring_size;
  std::uint32_t topic_bytes;
  std::int64_t pid;
  // The process's start time (/proc/PID/stat, field 22): a reader tells the
  // file of this process from one a dead process of the same pid left.
  std::uint64_t start_time;
};

// Shared between processes: every field a reader may see change is read and
// written through std::atomic_ref.
struct DelaySlot {
  static constexpr std::uint32_t free = 0, claiming = 1, in_use = 2;
  std::uint32_t state;
  std::uint32_t subscriber_id;
  char topic[256];      // NUL-terminated
  std::uint64_t count;  // delays recorded; the newest is at ring[(count - 1) % ring size]
  std::int64_t ring[1024];
};

inline constexpr std::uint32_t delay_file_version = 1;
inline constexpr std::uint32_t delay_slots = 256;
inline constexpr std::uint32_t delay_ring_size = 1024;
inline constexpr std::size_t delay_file_bytes =
    sizeof(DelayFileHeader) + delay_slots * sizeof(DelaySlot);

// The file's name for `pid`.
std::string delay_file_path(pid_t pid);
// A live process's start time as /proc/PID/stat gives it (field 22); nullopt
// when no process of that pid lives (a zombie does not).
std::optional<std::uint64_t> process_start_time(pid_t pid);

// One subscription's slot while it lives; records nothing when it has none
// (the file could not be made, or every slot is taken).
class DelayRecorder {
 public:
  DelayRecorder() = default;
  DelayRecorder(std::string_view topic, std::uint32_t subscriber_id);
  ~DelayRecorder();
  DelayRecorder(const DelayRecorder&) = delete;
  DelayRecorder& operator=(const DelayRecorder&) = delete;

  // The callback of a message published at `publish_time_ns` (steady clock)
  // starts now. One thread at a time per subscription.
  void record(std::int64_t publish_time_ns) noexcept {
    if (!slot_ || publish_time_ns == 0) return;
    record_now(publish_time_ns);
  }
  bool recording() const { return slot_ != nullptr; }

 private:
  void record_now(std::int64_t publish_time_ns) noexcept;
  DelaySlot* slot_ = nullptr;
  pid_t claimed_by_ = 0;  // a fork child's copy frees nothing of its parent's
};

}  // namespace agnocast::detail
