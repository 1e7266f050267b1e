#include "dds_names.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace agnocast_bridge {
namespace {

TEST(DdsNames, TopicGetsTheRosPrefix) {
  EXPECT_EQ(dds_topic_name("/points"), "rt/points");
  EXPECT_EQ(dds_topic_name("/robot/cmd_vel"), "rt/robot/cmd_vel");
}

TEST(DdsNames, TypeFollowsRos2OverDds) {
  EXPECT_EQ(dds_type_name("sensor_msgs/msg/PointCloud2"), "sensor_msgs::msg::dds_::PointCloud2_");
  EXPECT_EQ(dds_type_name("builtin_interfaces/msg/Time"), "builtin_interfaces::msg::dds_::Time_");
}

TEST(DdsNames, MalformedTypeIsRefused) {
  for (const char* bad :
       {"PointCloud2", "sensor_msgs/PointCloud2", "/msg/X", "a/msg/", "a/b/c/d", "raw:16:8"}) {
    EXPECT_THROW(dds_type_name(bad), std::invalid_argument) << bad;
  }
}

}  // namespace
}  // namespace agnocast_bridge
