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

TEST(DdsNames, ServiceFollowsRmwCycloneDds) {
  const DdsServiceTopics topics = dds_service_topic_names("/arm/enable");
  EXPECT_EQ(topics.request, "rq/arm/enableRequest");
  EXPECT_EQ(topics.reply, "rr/arm/enableReply");
  const ServiceTypeNames types = dds_service_type_names("example_interfaces/srv/AddTwoInts");
  EXPECT_EQ(types.request, "example_interfaces/srv/AddTwoInts_Request");
  EXPECT_EQ(types.response, "example_interfaces/srv/AddTwoInts_Response");
  EXPECT_EQ(types.dds_request, "example_interfaces::srv::dds_::AddTwoInts_Request_");
  EXPECT_EQ(types.dds_response, "example_interfaces::srv::dds_::AddTwoInts_Response_");
}

TEST(DdsNames, MalformedServiceTypeIsRefused) {
  for (const char* bad : {"AddTwoInts", "std_srvs/msg/SetBool", "std_srvs/srv/", "/srv/SetBool",
                          "a/srv/b/c", "std_srvs/srvX/SetBool"}) {
    EXPECT_THROW(dds_service_type_names(bad), std::invalid_argument) << bad;
  }
}

}  // namespace
}  // namespace agnocast_bridge
