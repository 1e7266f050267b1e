// rosbag2's channel metadata "offered_qos_profiles": the QoS of the
// publishers a topic had when it was recorded, as YAML. bag record writes it
// for readers that replay with the same QoS; bag play reads it back, from
// any writer: rmw's numbers (rosbag2 up to Humble and agnocast) or its words
// (rosbag2 from Iron on).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "agnocast/qos.hpp"

namespace agnocast::cli {

// The profiles of the publishers (depth, transient_local).
std::string offered_qos_profiles(const std::vector<std::pair<std::uint32_t, bool>>& publishers);

// What a player offers late subscribers: transient local when any recorded
// publisher was, with the deepest recorded depth (within the kernel's
// bounds). Without profiles, or with ones it cannot read, a volatile QoS of
// `default_depth`.
QoS played_qos(std::string_view offered_qos_profiles, std::size_t default_depth);

}  // namespace agnocast::cli
