#include "syscall_counter.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "tracepoint_counter.hpp"

namespace agnocast::bench {

std::optional<SyscallCounter> SyscallCounter::open(const std::vector<std::string>& names,
                                                   std::string* why) {
  SyscallCounter counter;
  std::vector<std::pair<std::string, std::string>> events{{"total", "raw_syscalls/sys_enter"}};
  for (const auto& name : names) events.emplace_back(name, "syscalls/sys_enter_" + name);
  for (const auto& [name, event] : events) {
    const auto id = tracepoint_id(event);
    const int group_fd = counter.fds_.empty() ? -1 : counter.fds_.front();
    const int fd = id ? open_tracepoint_counter(*id, 0, -1, group_fd, 0, true) : -1;
    if (fd < 0) {
      *why = "no counter for " + event + ": " +
             (id ? std::string(std::strerror(errno)) : std::string("no tracepoint in tracefs"));
      return std::nullopt;
    }
    counter.names_.push_back(name);
    counter.fds_.push_back(fd);
  }
  return counter;
}

SyscallCounter::~SyscallCounter() {
  for (int fd : fds_) ::close(fd);
}

SyscallCounter::SyscallCounter(SyscallCounter&& other) noexcept
    : names_(std::move(other.names_)), fds_(std::move(other.fds_)) {
  other.fds_.clear();
}

SyscallCounts SyscallCounter::take_reading() const {
  // PERF_FORMAT_GROUP: the number of counters, then each value.
  std::vector<std::uint64_t> values(1 + fds_.size());
  const ssize_t bytes = ::read(fds_.front(), values.data(), values.size() * sizeof values[0]);
  if (bytes != static_cast<ssize_t>(values.size() * sizeof values[0])) {
    throw std::runtime_error("reading the syscall counters failed");
  }
  SyscallCounts counts;
  for (std::size_t i = 0; i < names_.size(); ++i) {
    counts[names_[i]] = static_cast<std::int64_t>(values[1 + i]);
  }
  return counts;
}

SyscallCounts counted_between(const SyscallCounts& earlier, const SyscallCounts& later) {
  SyscallCounts between;
  for (const auto& [name, count] : later) between[name] = count - earlier.at(name);
  between["total"] -= 1;
  if (between.contains("read")) between["read"] -= 1;
  return between;
}

}  // namespace agnocast::bench
