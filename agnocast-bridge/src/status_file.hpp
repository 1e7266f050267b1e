// The bridge's fields of its status file (agnocast::bridge_status_path),
// written after the head every daemon writes (<agnocast/status.hpp>):
//   {"program":"agnocast-bridge","pid":42,...,"running":true,...,
//    "domain_id":0,
//    "topics":[{"name":"/points","type":"sensor_msgs/msg/PointCloud2",
//               "direction":"to_dds","dds_topic":"rt/points",
//               "dds_type":"sensor_msgs::msg::dds_::PointCloud2_",
//               "relayed":120,"dropped":0,"errors":0}],
//    "services":[{"name":"/add_two_ints","type":"example_interfaces/srv/AddTwoInts",
//                 "direction":"from_dds","dds_request_topic":"rq/add_two_intsRequest",
//                 "dds_reply_topic":"rr/add_two_intsReply",
//                 "dds_request_type":"example_interfaces::srv::dds_::AddTwoInts_Request_",
//                 "dds_response_type":"example_interfaces::srv::dds_::AddTwoInts_Response_",
//                 "relayed":3,"dropped":1,"errors":0}]}
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

// relayed: calls answered; dropped: calls not answered; errors: bad bytes, DDS errors.
struct BridgedServiceStatus {
  const ServiceConfig* service = nullptr;
  std::uint64_t relayed = 0;
  std::uint64_t dropped = 0;
  std::uint64_t errors = 0;
};

struct BridgeStatus {
  std::uint32_t domain_id = 0;
  std::vector<TopicStatus> topics;
  std::vector<BridgedServiceStatus> services;
};

// {"domain_id":..,"topics":[..],"services":[..]}
nlohmann::json status_body(const BridgeStatus& status);

}  // namespace agnocast_bridge
