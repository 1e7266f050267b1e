#include "tracepoint_counter.hpp"

#include <linux/perf_event.h>
#include <sys/mount.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <fstream>

namespace agnocast::bench {
namespace {

constexpr const char* tracefs = "/sys/kernel/tracing";

std::optional<std::uint64_t> read_id(const std::string& event) {
  std::ifstream file(std::string(tracefs) + "/events/" + event + "/id");
  std::uint64_t id = 0;
  if (!(file >> id)) return std::nullopt;
  return id;
}

}  // namespace

std::optional<std::uint64_t> tracepoint_id(const std::string& event) {
  if (const auto id = read_id(event)) return id;
  // The VM mounts nothing it does not need: tracefs may not be there yet.
  mount("tracefs", tracefs, "tracefs", 0, nullptr);
  return read_id(event);
}

int open_tracepoint_counter(std::uint64_t id, int pid, int cpu, int group_fd, unsigned long flags,
                            bool in_group_format) {
  perf_event_attr attr{};
  attr.type = PERF_TYPE_TRACEPOINT;
  attr.size = sizeof attr;
  attr.config = id;
  if (in_group_format) attr.read_format = PERF_FORMAT_GROUP;
  return static_cast<int>(syscall(SYS_perf_event_open, &attr, pid, cpu, group_fd, flags));
}

}  // namespace agnocast::bench
