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

}  // namespace agnocast_bridge
