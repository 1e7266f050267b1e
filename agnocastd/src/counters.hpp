// What agnocastd has removed since it started (shown by agnocast-cli daemon status).
#pragma once

#include <cstdint>

namespace agnocastd {

struct Counters {
  std::uint64_t processes_cleaned = 0;
  std::uint64_t queues_removed = 0;
  std::uint64_t shm_removed = 0;
};

}  // namespace agnocastd
