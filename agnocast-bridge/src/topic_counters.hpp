// What the bridge did with one bridged topic, for its status file.
#pragma once

#include <atomic>
#include <cstdint>

namespace agnocast_bridge {

struct TopicCounters {
  // Messages handed on to the other side.
  std::atomic<std::uint64_t> relayed{0};
  // Messages lost on the way: a reliable DDS write that timed out, or an
  // agnocast message with no pool memory left for it. Messages the kernel or
  // DDS discarded before the bridge saw them are added when the status is written.
  std::atomic<std::uint64_t> dropped{0};
  // Messages that could not be relayed: bytes that are not valid XCDR1 for the
  // type, a value beyond a declared bound, a DDS error.
  std::atomic<std::uint64_t> errors{0};
};

}  // namespace agnocast_bridge
