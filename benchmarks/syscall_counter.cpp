#include "syscall_counter.hpp"

#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/mount.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace agnocast::bench {
namespace {

constexpr const char* tracefs = "/sys/kernel/tracing";

std::optional<std::uint64_t> tracepoint_id(const std::string& event) {
  std::ifstream file(std::string(tracefs) + "/events/" + event + "/id");
  std::uint64_t id = 0;
  if (!(file >> id)) return std::nullopt;
  return id;
}

int open_counter(std::uint64_t id, int group_fd) {
  perf_event_attr attr{};
  attr.type = PERF_TYPE_TRACEPOINT;
  attr.size = sizeof attr;
  attr.config = id;
  attr.read_format = PERF_FORMAT_GROUP;
  return static_cast<int>(syscall(SYS_perf_event_open, &attr, 0, -1, group_fd, 0));
}

}  // namespace

std::optional<SyscallCounter> SyscallCounter::open(const std::vector<std::string>& names,
                                                   std::string* why) {
  if (!tracepoint_id("raw_syscalls/sys_enter")) {
    mount("tracefs", tracefs, "tracefs", 0, nullptr);
  }
  SyscallCounter counter;
  std::vector<std::pair<std::string, std::string>> events{{"total", "raw_syscalls/sys_enter"}};
  for (const auto& name : names) events.emplace_back(name, "syscalls/sys_enter_" + name);
  for (const auto& [name, event] : events) {
    const auto id = tracepoint_id(event);
    const int fd = id ? open_counter(*id, counter.fds_.empty() ? -1 : counter.fds_.front()) : -1;
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
