// Counts the calling thread's heap allocations through operator new, which
// agnocast-bench replaces: the fixed-rate run reports how many the library's
// receive path makes per message.
#pragma once

#include <cstdint>

namespace agnocast::bench {

std::uint64_t allocations_by_this_thread();

}  // namespace agnocast::bench
