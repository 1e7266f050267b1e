// Cleanup after a dead agnocast process, from the exit records the kernel
// module queues for it.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "agnocast/supervise.hpp"
#include "counters.hpp"
#include "host.hpp"

namespace agnocastd {

struct DeadProcess {
  pid_t pid = 0;
  std::vector<std::string> queues;  // e.g. "/chatter@1"
};

// Turns the record stream into whole dead processes: a process's queue
// records come before its process record, possibly in an earlier read.
class DeadProcessCollector {
 public:
  std::vector<DeadProcess> add(const std::vector<agnocast::ExitRecord>& records);
  // How many records the kernel discarded unread since the last call.
  std::uint64_t take_lost();

 private:
  std::map<pid_t, std::vector<std::string>> pending_queues_;
  std::uint64_t lost_ = 0;
};

// Removes what one dead process left: its queues (no publisher can wake a
// dead subscriber any more), then counts it.  Its pool is a memfd, which the
// kernel frees itself.
void clean_dead_process(const DeadProcess& process, Host& host, Counters& counters);

// Cleans up after the processes these records complete; when the kernel
// discarded records unread, also sweeps at once, since only a sweep finds what
// the lost ones named. True when anything was cleaned or swept.
bool handle_exit_records(const std::vector<agnocast::ExitRecord>& records,
                         DeadProcessCollector& collector, Host& host, Counters& counters);

}  // namespace agnocastd
