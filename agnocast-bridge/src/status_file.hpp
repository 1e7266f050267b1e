// The bridge's status file, one JSON object replaced atomically, 0644:
//   {"running":true,"pid":42,"domain_id":0,"started_at":1700000000,"uptime_s":12,
//    "topics":[{"name":"/points","type":"sensor_msgs/msg/PointCloud2",
//               "direction":"to_dds","dds_topic":"rt/points",
//               "dds_type":"sensor_msgs::msg::dds_::PointCloud2_",
//               "relayed":120,"dropped":0,"errors":0}]}
// Written at start, every second and with "running":false on a clean stop.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "config.hpp"

namespace agnocast_bridge {

inline constexpr std::string_view status_path = "/run/agnocast/bridge.json";
inline constexpr std::string_view lock_path = "/run/agnocast/bridge.lock";

struct TopicStatus {
  const TopicConfig* topic = nullptr;
  std::uint64_t relayed = 0;
  std::uint64_t dropped = 0;
  std::uint64_t errors = 0;
};

struct BridgeStatus {
  bool running = true;
  int pid = 0;
  std::uint32_t domain_id = 0;
  std::int64_t started_at = 0;  // Unix seconds
  std::int64_t uptime_s = 0;
  std::vector<TopicStatus> topics;
};

std::string status_json(const BridgeStatus& status);
// Replaces path (agnocast_service::write_file_atomically); throws
// std::system_error when the file cannot be written.
void write_status_file(const std::string& path, const BridgeStatus& status);

}  // namespace agnocast_bridge
