// The memory mapping that holds an address, read from /proc/self/maps: for a
// message, the pool it lives in (the publisher's own, or a subscriber's view).
#pragma once

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

namespace seed {

struct Mapping {
  std::uintptr_t begin = 0;
  std::uintptr_t end = 0;
  bool contains(const void* ptr) const {
    const auto at = reinterpret_cast<std::uintptr_t>(ptr);
    return at >= begin && at < end;
  }
};

inline Mapping mapping_of(const void* ptr) {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) {
    std::istringstream fields(line);
    std::string range;
    fields >> range;
    const auto dash = range.find('-');
    Mapping mapping{std::stoull(range.substr(0, dash), nullptr, 16),
                    std::stoull(range.substr(dash + 1), nullptr, 16)};
    if (mapping.contains(ptr)) return mapping;
  }
  return {};
}

// The bytes of seed::Msg number seq, so that the subscriber can check them.
inline std::uint8_t payload_byte(std::uint64_t seq, std::size_t index) {
  return static_cast<std::uint8_t>(seq * 31 + index * 7);
}
inline std::string frame_id(std::uint64_t seq) {
  return "frame " + std::to_string(seq) + ", long enough to live on the heap";
}
inline std::size_t payload_size(std::uint64_t seq) { return 1000 + seq % 7 * 10000; }
inline std::size_t point_count(std::uint64_t seq) { return 10 + seq % 50; }
inline std::size_t tag_count(std::uint64_t seq) { return 1 + seq % 4; }

}  // namespace seed
