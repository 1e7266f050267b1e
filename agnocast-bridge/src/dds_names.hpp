// How ROS 2 over DDS names things, so that a ROS 2 node finds the bridge's topics.
#pragma once

#include <string>
#include <string_view>

namespace agnocast_bridge {

// "/points" -> "rt/points" (ROS 2's prefix for topics).
std::string dds_topic_name(std::string_view agnocast_topic);

// "sensor_msgs/msg/PointCloud2" -> "sensor_msgs::msg::dds_::PointCloud2_";
// throws std::invalid_argument unless the name has the form "pkg/msg/Type".
std::string dds_type_name(std::string_view ros_type_name);

// A service as rmw_cyclonedds_cpp puts it on DDS: "/add_two_ints" travels on
// "rq/add_two_intsRequest" (requests) and "rr/add_two_intsReply" (replies).
struct DdsServiceTopics {
  std::string request;
  std::string reply;
};
DdsServiceTopics dds_service_topic_names(std::string_view agnocast_service);

// "example_interfaces/srv/AddTwoInts" -> the agnocast message types of its
// parts, "example_interfaces/srv/AddTwoInts_Request" and "..._Response", and
// their DDS types "example_interfaces::srv::dds_::AddTwoInts_Request_" and
// "..._Response_"; throws std::invalid_argument unless the name has the form
// "pkg/srv/Name".
struct ServiceTypeNames {
  std::string request;
  std::string response;
  std::string dds_request;
  std::string dds_response;
};
ServiceTypeNames dds_service_type_names(std::string_view ros_service_type);

}  // namespace agnocast_bridge
