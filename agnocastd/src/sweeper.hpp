// The sweep: removes what no exit record will ever name — queues and delay
// records left by crashes before the daemon ran or by an earlier module load.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "counters.hpp"
#include "host.hpp"

namespace agnocastd {

// Queue names ("/x@1") of the agnocast-pattern files in listed_files that no
// live subscriber owns. listed_files must be read before live_queues: a queue
// appears only after the kernel lists its subscriber, so one created between
// the two reads is in live_queues.
std::vector<std::string> stale_queues(const std::vector<std::string>& listed_files,
                                      const std::set<std::string>& live_queues);

// Removes stale queues, and the delay records of processes gone. Removes
// no queue when the kernel cannot be asked which are live.
void sweep(Host& host, Counters& counters);

}  // namespace agnocastd
