#include "delay/delay_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <sstream>

#include "agnocast/inspect.hpp"
#include "agnocast/log.hpp"
#include "log_internal.hpp"

namespace agnocast::detail {
namespace {

constexpr char delay_magic[8] = {'a', 'g', 'n', 'd', 'e', 'l', 'a', 'y'};

DelaySlot* slots_of(void* file) {
  return reinterpret_cast<DelaySlot*>(static_cast<std::byte*>(file) + sizeof(DelayFileHeader));
}

// This process's file while it has recorders: made for the first, removed
// with the last (a process that ends with _exit after its subscriptions
// leaves nothing), and at exit. A fork child makes its own.
class DelayFile {
 public:
  // A free slot, claimed; nullptr when the file cannot be made (said once,
  // in the log) or every slot is taken.
  static DelaySlot* claim(std::string_view topic, std::uint32_t subscriber_id) {
    if (topic.size() >= sizeof(DelaySlot::topic)) return nullptr;
    std::lock_guard lock(mutex_);
    const pid_t pid = ::getpid();
    if (owner_ != pid) {
      // A fork child: the mapping is its parent's file, left alone.
      owner_ = pid;
      base_ = nullptr;
      users_ = 0;
      failure_logged_ = false;
    }
    if (!base_) base_ = create(pid);
    if (!base_) return nullptr;
    DelaySlot* slots = slots_of(base_);
    for (std::uint32_t i = 0; i < delay_slots; ++i) {
      std::uint32_t expected = DelaySlot::free;
      if (!std::atomic_ref(slots[i].state)
               .compare_exchange_strong(expected, DelaySlot::claiming, std::memory_order_acquire)) {
        continue;
      }
      DelaySlot& slot = slots[i];
      slot.subscriber_id = subscriber_id;
      std::memset(slot.topic, 0, sizeof slot.topic);
      std::memcpy(slot.topic, topic.data(), topic.size());
      std::atomic_ref(slot.count).store(0, std::memory_order_relaxed);
      std::atomic_ref(slot.state).store(DelaySlot::in_use, std::memory_order_release);
      ++users_;
      return &slot;
    }
    return nullptr;
  }

  // Frees a slot this process claimed.
  static void release(DelaySlot* slot) {
    std::lock_guard lock(mutex_);
    if (!base_) return;
    std::atomic_ref(slot->state).store(DelaySlot::free, std::memory_order_release);
    if (--users_ > 0) return;
    ::unlink(delay_file_path(owner_).c_str());
    ::munmap(base_, delay_file_bytes);
    base_ = nullptr;
  }

 private:
  static void* create(pid_t pid) {
    const std::string path = delay_file_path(pid);
    const std::optional<std::uint64_t> start_time = process_start_time(pid);
    int fd = -1;
    for (int attempt = 0; attempt < 2 && fd < 0; ++attempt) {
      fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
      if (fd < 0 && errno == EEXIST && attempt == 0) {
        // Left by a dead process of this pid: ours to replace when it is
        // this user's (in the sticky /dev/shm no one else could remove it).
        struct stat status {};
        if (::lstat(path.c_str(), &status) == 0 && status.st_uid == ::geteuid()) {
          ::unlink(path.c_str());
        }
      }
    }
    void* base = MAP_FAILED;
    if (fd >= 0 && start_time && ::fchmod(fd, 0644) == 0 &&
        ::ftruncate(fd, static_cast<off_t>(delay_file_bytes)) == 0) {
      base = ::mmap(nullptr, delay_file_bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    }
    const int error = errno;
    if (fd >= 0) ::close(fd);
    if (base == MAP_FAILED) {
      if (fd >= 0) ::unlink(path.c_str());
      if (!failure_logged_) {
        failure_logged_ = true;
        log(LogLevel::warning, "cannot make " + path + " (" + std::strerror(error) +
                                   "): agnocast-cli topic delay shows nothing of this process");
      }
      return nullptr;
    }
    auto* header = static_cast<DelayFileHeader*>(base);
    header->version = delay_file_version;
    header->slot_count = delay_slots;
    header->ring_size = delay_ring_size;
    header->topic_bytes = sizeof(DelaySlot::topic);
    header->pid = pid;
    header->start_time = *start_time;
    std::atomic_thread_fence(std::memory_order_release);
    std::memcpy(header->magic, delay_magic, sizeof delay_magic);
    static bool unlink_at_exit = false;
    if (!unlink_at_exit) {
      unlink_at_exit = true;
      std::atexit(remove_at_exit);
    }
    return base;
  }

  // The name goes; the mapping stays (a callback may still record).
  static void remove_at_exit() {
    std::lock_guard lock(mutex_);
    if (base_ && owner_ == ::getpid()) ::unlink(delay_file_path(owner_).c_str());
  }

  static inline std::mutex mutex_;
  static inline void* base_ = nullptr;
  static inline pid_t owner_ = 0;
  static inline std::size_t users_ = 0;
  static inline bool failure_logged_ = false;
};

// An unmapping on every return.
struct ReadOnlyMapping {
  void* base = MAP_FAILED;
  ~ReadOnlyMapping() {
    if (base != MAP_FAILED) ::munmap(base, delay_file_bytes);
  }
};

}  // namespace

std::string delay_file_path(pid_t pid) { return delay_file_prefix + std::to_string(pid); }

namespace {

// What /proc/PID/stat says of a process; nullopt when there is none.
struct ProcessStat {
  std::string state;             // field 3: "R", "S", ..., "Z" (zombie), "X" (dead)
  std::uint64_t flags = 0;       // field 9: the kernel's PF_* flags
  std::uint64_t start_time = 0;  // field 22
};

std::optional<std::uint64_t> parse_unsigned(const std::string& text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<ProcessStat> read_process_stat(pid_t pid) {
  // Plain reads: a stream's read of a process that dies meanwhile throws.
  const int fd = ::open(("/proc/" + std::to_string(pid) + "/stat").c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::string text;
  char buffer[512];
  for (ssize_t got; (got = ::read(fd, buffer, sizeof buffer)) > 0;) {
    text.append(buffer, static_cast<std::size_t>(got));
  }
  ::close(fd);
  // The command name may hold spaces and parentheses: fields follow the last ')'.
  const std::size_t close = text.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream fields(text.substr(close + 1));
  ProcessStat stat{};
  std::string field;
  for (int index = 3; index <= 22; ++index) {
    if (!(fields >> field)) return std::nullopt;
    if (index == 3) stat.state = field;
    if (index == 9 || index == 22) {
      const std::optional<std::uint64_t> number = parse_unsigned(field);
      if (!number) return std::nullopt;
      (index == 9 ? stat.flags : stat.start_time) = *number;
    }
  }
  return stat;
}

bool lives(const ProcessStat& stat) { return stat.state != "Z" && stat.state != "X"; }

}  // namespace

std::optional<std::uint64_t> process_start_time(pid_t pid) {
  const std::optional<ProcessStat> stat = read_process_stat(pid);
  if (!stat || !lives(*stat)) return std::nullopt;
  return stat->start_time;
}

DelayRecorder::DelayRecorder(std::string_view topic, std::uint32_t subscriber_id)
    : slot_(DelayFile::claim(topic, subscriber_id)), claimed_by_(::getpid()) {}

DelayRecorder::~DelayRecorder() {
  if (slot_ && claimed_by_ == ::getpid()) DelayFile::release(slot_);
}

void DelayRecorder::record_now(std::int64_t publish_time_ns) noexcept {
  const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::steady_clock::now().time_since_epoch())
                               .count();
  std::atomic_ref count(slot_->count);
  const std::uint64_t n = count.load(std::memory_order_relaxed);
  std::atomic_ref(slot_->ring[n % delay_ring_size])
      .store(std::max<std::int64_t>(now - publish_time_ns, 0), std::memory_order_relaxed);
  count.store(n + 1, std::memory_order_release);
}

}  // namespace agnocast::detail

namespace agnocast {

using detail::DelayFileHeader;
using detail::DelaySlot;

std::optional<RecordedDelays> recorded_delays(pid_t pid, const std::string& topic,
                                              std::uint32_t subscriber_id) {
  const std::string path = detail::delay_file_path(pid);
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return std::nullopt;
  struct stat status {};
  detail::ReadOnlyMapping mapping;
  if (::fstat(fd, &status) == 0 && S_ISREG(status.st_mode) &&
      static_cast<std::size_t>(status.st_size) == detail::delay_file_bytes) {
    mapping.base = ::mmap(nullptr, detail::delay_file_bytes, PROT_READ, MAP_SHARED, fd, 0);
  }
  ::close(fd);
  if (mapping.base == MAP_FAILED) return std::nullopt;
  // Everything in it is another process's word: checked before it is believed.
  const auto* header = static_cast<const DelayFileHeader*>(mapping.base);
  if (std::memcmp(header->magic, detail::delay_magic, sizeof header->magic) != 0)
    return std::nullopt;
  std::atomic_thread_fence(std::memory_order_acquire);
  if (header->version != detail::delay_file_version || header->slot_count != detail::delay_slots ||
      header->ring_size != detail::delay_ring_size ||
      header->topic_bytes != sizeof(DelaySlot::topic) || header->pid != pid ||
      detail::process_start_time(pid) != header->start_time) {
    return std::nullopt;
  }
  auto* slots = const_cast<DelaySlot*>(reinterpret_cast<const DelaySlot*>(
      static_cast<const std::byte*>(mapping.base) + sizeof(DelayFileHeader)));
  for (std::uint32_t i = 0; i < detail::delay_slots; ++i) {
    DelaySlot& slot = slots[i];
    if (std::atomic_ref(slot.state).load(std::memory_order_acquire) != DelaySlot::in_use ||
        slot.subscriber_id != subscriber_id ||
        std::memchr(slot.topic, '\0', sizeof slot.topic) == nullptr || topic != slot.topic) {
      continue;
    }
    RecordedDelays delays;
    delays.count = std::atomic_ref(slot.count).load(std::memory_order_acquire);
    const std::uint64_t kept = std::min<std::uint64_t>(delays.count, detail::delay_ring_size);
    std::vector<std::int64_t> values;
    for (std::uint64_t index = delays.count - kept; index < delays.count; ++index) {
      values.push_back(std::atomic_ref(slot.ring[index % detail::delay_ring_size])
                           .load(std::memory_order_relaxed));
    }
    // Those the writer reached again while they were copied are not theirs.
    const std::uint64_t now = std::atomic_ref(slot.count).load(std::memory_order_acquire);
    const std::uint64_t overwritten =
        now > detail::delay_ring_size ? now - detail::delay_ring_size : 0;
    const std::uint64_t first = delays.count - kept;
    const std::uint64_t skip = overwritten > first ? std::min(overwritten - first, kept) : 0;
    delays.newest_ns.assign(values.begin() + static_cast<std::ptrdiff_t>(skip), values.end());
    return delays;
  }
  return std::nullopt;
}

std::vector<pid_t> delay_record_pids() {
  const std::string path = detail::delay_file_prefix;
  const std::string directory = path.substr(0, path.rfind('/'));
  const std::string prefix = path.substr(path.rfind('/') + 1);
  std::vector<pid_t> pids;
  DIR* dir = ::opendir(directory.c_str());
  if (!dir) return pids;
  while (const dirent* entry = ::readdir(dir)) {
    const std::string_view name = entry->d_name;
    if (!name.starts_with(prefix)) continue;
    const std::string_view digits = name.substr(prefix.size());
    if (digits.empty() || digits.size() > 9 ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      continue;
    }
    pids.push_back(static_cast<pid_t>(std::stol(std::string(digits))));
  }
  ::closedir(dir);
  return pids;
}

bool remove_stale_delay_record(pid_t pid, bool exit_reported) {
  const std::string path = detail::delay_file_path(pid);
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return false;
  DelayFileHeader header{};
  const bool whole = ::pread(fd, &header, sizeof header, 0) == sizeof header;
  ::close(fd);
  const std::optional<detail::ProcessStat> stat = detail::read_process_stat(pid);
  // A process whose exit the kernel reported may still be on its way out
  // (PF_EXITING): gone all the same. A new process of the pid is not exiting.
  constexpr std::uint64_t exiting = 0x4;  // PF_EXITING
  const bool gone = !stat || !detail::lives(*stat) || (exit_reported && (stat->flags & exiting));
  // A live process's file whose header is not written yet is its own.
  const bool made =
      whole && std::memcmp(header.magic, detail::delay_magic, sizeof header.magic) == 0;
  const bool stale = gone || (made && header.start_time != stat->start_time);
  return stale && ::unlink(path.c_str()) == 0;
}

}  // namespace agnocast
