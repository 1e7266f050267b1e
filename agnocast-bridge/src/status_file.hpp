// The bridge's fields of its status file (agnocast::bridge_status_path),
// written after the head every daemon writes (<agnocast/status.hpp>):
//   {"program":"agnocast-bridge","pid":42,...,"running":true,...,
//    "domain_id":0,
//    "topics":[{"name":"/points","type":"sensor_msgs/msg/PointCloud2",
//               "direction":"to_dds","dds_topic":"rt/points",
//               "dds_type":"sensor_msgs::msg::dds_::PointCloud2_",
//               "relayed":120,"dropped":0,"errors":0}]}
// Written at start, every second, at stop and with "state":"stopped" last.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "config.hpp"

namespace agnocast_bridge {

struct TopicStatus {
  const TopicConfig* topic = nullptr;
  std::uint64_t relayed = 0;
  std::uint64_t dropped = 0;
  std::uint64_t errors = 0;
};

struct BridgeStatus {
  std::uint32_t domain_id = 0;
  std::vector<TopicStatus> topics;
};

// {"domain_id":..,"topics":[..]}
nlohmann::json status_body(const BridgeStatus& status);

}  // namespace agnocast_bridge
