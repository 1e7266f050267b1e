// Counting a kernel tracepoint's hits with perf: what the syscall counter and
// the window counters share.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace agnocast::bench {

// The perf id of tracefs event CATEGORY/NAME (e.g. "sched/sched_switch"),
// mounting tracefs first if it is not; nullopt if the kernel lacks it.
std::optional<std::uint64_t> tracepoint_id(const std::string& event);

// A perf counter of tracepoint ID, as perf_event_open(2) takes PID, CPU,
// GROUP_FD and FLAGS; read_format PERF_FORMAT_GROUP when IN_GROUP_FORMAT.
// -1 with errno set on failure.
int open_tracepoint_counter(std::uint64_t id, int pid, int cpu, int group_fd, unsigned long flags,
                            bool in_group_format);

}  // namespace agnocast::bench
