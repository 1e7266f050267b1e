// A message type as people write them: standard containers, nothing from
// agnocast. Publishers of it run with the allocation hook.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace seed {

struct Point {
  double x = 0;
  double y = 0;
  double z = 0;
};

struct Tag {
  std::string key;
  std::vector<std::int32_t> values;
};

struct Msg {
  std::uint64_t seq = 0;
  std::vector<std::uint8_t> payload;
  std::string frame_id;
  std::vector<Point> points;
  std::vector<Tag> tags;  // nested: vectors and strings inside a vector
};

}  // namespace seed
