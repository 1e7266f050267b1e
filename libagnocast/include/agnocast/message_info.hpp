#pragma once

#include <cstdint>

namespace agnocast {

// What a subscription callback may learn about the message besides its contents.
struct MessageInfo {
  std::uint32_t publisher_id = 0;  // the publisher's id on the topic (agnocast-cli shows it)
  std::uint64_t entry_id = 0;      // the kernel's entry id, increasing per topic
  std::int64_t publish_time = 0;   // std::chrono::steady_clock nanoseconds at publish()
  std::uint64_t bytes = 0;         // the message and the pool memory its containers use
};

}  // namespace agnocast
