// Message types shared by the guide's examples.
#pragma once

#include <agnocast/agnocast.hpp>
#include <array>
#include <cstdint>

namespace robot {

// Trivially copyable: publishable as it is (no pointers, no std::string).
struct Pose {
  double x = 0, y = 0, yaw = 0;
};

// Sized at run time: agnocast::vector and agnocast::string allocate in the
// publisher's shared pool, so subscribers read them in place.
struct Scan {
  std::uint64_t seq = 0;
  agnocast::string frame_id;
  std::array<float, 2> angle_range{};
  agnocast::vector<float> ranges;
};

}  // namespace robot

// Declares the fields, so tools can show the message and both sides check
// they agree on its layout.
AGNOCAST_MESSAGE(robot::Scan, "robot/msg/Scan", seq, frame_id, angle_range, ranges);
