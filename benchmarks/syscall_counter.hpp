// Counts the system calls the calling thread makes, by name, with the
// kernel's syscall tracepoints as perf counters (no tracer stops the thread,
// so the counted code runs as it does unobserved).  Needs tracefs, which it
// mounts at /sys/kernel/tracing when nothing is there yet, and root.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace agnocast::bench {

using SyscallCounts = std::map<std::string, std::int64_t>;  // "total" and each counted name

class SyscallCounter {
 public:
  // Empty when the kernel offers no syscall tracepoints; `why` then says why.
  static std::optional<SyscallCounter> open(const std::vector<std::string>& names,
                                            std::string* why);
  ~SyscallCounter();
  SyscallCounter(SyscallCounter&& other) noexcept;
  SyscallCounter(const SyscallCounter&) = delete;
  SyscallCounter& operator=(const SyscallCounter&) = delete;
  SyscallCounter& operator=(SyscallCounter&&) = delete;

  // Counts so far.  The read is itself one system call, included in the
  // next reading: take_reading() - earlier reading - 1 read is what ran between.
  SyscallCounts take_reading() const;

 private:
  SyscallCounter() = default;
  std::vector<std::string> names_;  // "total" first, in the group's order
  std::vector<int> fds_;
};

// later - earlier, with the read that took `later` taken out of "total" and "read".
SyscallCounts counted_between(const SyscallCounts& earlier, const SyscallCounts& later);

}  // namespace agnocast::bench
