#include "status_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "agnocast_service/status_file.hpp"

namespace agnocast_bridge {
namespace {

TEST(StatusFile, CountersPerTopicAsJson) {
  TopicConfig points{"/points", "sensor_msgs/msg/PointCloud2", Direction::to_dds, {}};
  TopicConfig cmd{"/cmd_vel", "geometry_msgs/msg/Twist", Direction::from_dds, {}};
  BridgeStatus status{7, {{&points, 10, 1, 2}, {&cmd, 3, 0, 0}}, {}};
  const agnocast::ServiceStatus head{
      "agnocast-bridge", 42, "0.1.0", agnocast::ServiceState::running, 1700000000, 5, 1700000005};

  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("bridge-status-" + std::to_string(::getpid()));
  const std::string path = (dir / "bridge.json").string();
  // As the service loop writes it: the head, then the bridge's fields.
  agnocast_service::write_status_file(path, head, status_body(status));
  std::ifstream file(path);
  const auto json = nlohmann::json::parse(file);
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::all,
            std::filesystem::perms(0644));
  std::filesystem::remove_all(dir);

  EXPECT_EQ(json["running"], true);
  EXPECT_EQ(json["pid"], 42);
  EXPECT_EQ(json["domain_id"], 7);
  ASSERT_EQ(json["topics"].size(), 2u);
  const auto& first = json["topics"][0];
  EXPECT_EQ(first["name"], "/points");
  EXPECT_EQ(first["direction"], "to_dds");
  EXPECT_EQ(first["dds_topic"], "rt/points");
  EXPECT_EQ(first["dds_type"], "sensor_msgs::msg::dds_::PointCloud2_");
  EXPECT_EQ(first["relayed"], 10);
  EXPECT_EQ(first["dropped"], 1);
  EXPECT_EQ(first["errors"], 2);
  EXPECT_EQ(json["topics"][1]["direction"], "from_dds");
  EXPECT_EQ(json["topics"][1]["relayed"], 3);
}

TEST(StatusFile, CountersPerServiceAsJson) {
  ServiceConfig add{"/add_two_ints", "example_interfaces/srv/AddTwoInts", Direction::from_dds, {}};
  const BridgeStatus status{0, {}, {{&add, 3, 1, 0}}};
  const auto json = status_body(status);
  ASSERT_EQ(json["services"].size(), 1u);
  const auto& service = json["services"][0];
  EXPECT_EQ(service["name"], "/add_two_ints");
  EXPECT_EQ(service["type"], "example_interfaces/srv/AddTwoInts");
  EXPECT_EQ(service["direction"], "from_dds");
  EXPECT_EQ(service["dds_request_topic"], "rq/add_two_intsRequest");
  EXPECT_EQ(service["dds_reply_topic"], "rr/add_two_intsReply");
  EXPECT_EQ(service["dds_request_type"], "example_interfaces::srv::dds_::AddTwoInts_Request_");
  EXPECT_EQ(service["dds_response_type"], "example_interfaces::srv::dds_::AddTwoInts_Response_");
  EXPECT_EQ(service["relayed"], 3);
  EXPECT_EQ(service["dropped"], 1);
  EXPECT_EQ(service["errors"], 0);
}

}  // namespace
}  // namespace agnocast_bridge
