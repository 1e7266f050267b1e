// The shipped standard set, beyond what the generated per-package tests check
// for every type (tests/standard_package_test.cpp.in): hashes, exact renderings,
// exact bytes, bounds and defaults of nested messages.
#include <gtest/gtest.h>

#include <agnocast/cdr.hpp>
#include <agnocast/message_render.hpp>
#include <builtin_interfaces/msg/duration.hpp>
#include <builtin_interfaces/msg/time.hpp>
#include <geometry_msgs/msg/point.hpp>
#include <geometry_msgs/msg/pose.hpp>
#include <geometry_msgs/msg/transform.hpp>
#include <geometry_msgs/msg/vector3.hpp>
#include <iostream>
#include <sensor_msgs/msg/image.hpp>
#include <sensor_msgs/msg/nav_sat_fix.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <set>
#include <shape_msgs/msg/solid_primitive.hpp>
#include <std_msgs/msg/empty.hpp>
#include <std_msgs/msg/string.hpp>
#include <unique_identifier_msgs/msg/uuid.hpp>
#include <visualization_msgs/msg/interactive_marker_update.hpp>

#include "test_support.hpp"

namespace {

using standard_messages_test::install_test_runtime;

class StandardMessage : public ::testing::Test {
 protected:
  void SetUp() override { install_test_runtime(); }
};

TEST(StandardSet, HashesAreDistinct) {
  const std::set<std::uint64_t> hashes{
      agnocast::message_traits<geometry_msgs::msg::Vector3>::type_hash,
      agnocast::message_traits<geometry_msgs::msg::Point>::type_hash,
      agnocast::message_traits<geometry_msgs::msg::Pose>::type_hash,
      agnocast::message_traits<geometry_msgs::msg::Transform>::type_hash,
      agnocast::message_traits<sensor_msgs::msg::PointCloud2>::type_hash,
      agnocast::message_traits<sensor_msgs::msg::Image>::type_hash,
      agnocast::message_traits<builtin_interfaces::msg::Time>::type_hash,
      agnocast::message_traits<builtin_interfaces::msg::Duration>::type_hash};
  // Vector3 and Point, Time and Duration share a layout, not a name.
  EXPECT_EQ(hashes.size(), 8u);
}

TEST(StandardSet, TypeNamesAreRos2s) {
  EXPECT_EQ(agnocast::message_traits<std_msgs::msg::String>::type_name, "std_msgs/msg/String");
  EXPECT_EQ(agnocast::message_traits<unique_identifier_msgs::msg::UUID>::type_name,
            "unique_identifier_msgs/msg/UUID");
}

// The deepest type of the set still fits the kernel's schema bound, with
// the .msg text of every type it nests.
TEST(StandardSet, InteractiveMarkerUpdateHasAllItsNestedTypes) {
  const auto blob = agnocast::schema_of<visualization_msgs::msg::InteractiveMarkerUpdate>();
  const agnocast::Schema schema = agnocast::parse_schema(blob);
  std::cout << "InteractiveMarkerUpdate: " << schema.types.size() << " types, " << blob.size()
            << " schema bytes\n";
  std::set<std::string> names;
  for (const agnocast::SchemaType& type : schema.types) {
    names.insert(type.name);
    EXPECT_FALSE(type.definition.empty()) << type.name;
  }
  for (const char* name : {"visualization_msgs/msg/InteractiveMarker",
                           "visualization_msgs/msg/InteractiveMarkerControl",
                           "visualization_msgs/msg/Marker", "visualization_msgs/msg/MeshFile",
                           "sensor_msgs/msg/CompressedImage", "builtin_interfaces/msg/Duration"}) {
    EXPECT_TRUE(names.contains(name)) << name;
  }
}

TEST_F(StandardMessage, StringIsWhatRos2Sends) {
  std_msgs::msg::String text;
  text.data = "hi";
  const std::vector<std::uint8_t> expected{0, 1, 0, 0, 3, 0, 0, 0, 'h', 'i', 0};
  EXPECT_EQ(agnocast::cdr::serialize(text), expected);
  const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<decltype(text)>());
  EXPECT_EQ(agnocast::render_message_json(&text, schema), R"({"data":"hi"})");
}

TEST_F(StandardMessage, EmptyHasOneByteAsInRos2) {
  const std::vector<std::uint8_t> expected{0, 1, 0, 0, 0};
  EXPECT_EQ(agnocast::cdr::serialize(std_msgs::msg::Empty{}), expected);
}

TEST_F(StandardMessage, NestedDefaultsApply) {
  const geometry_msgs::msg::Pose pose;
  EXPECT_EQ(pose.orientation.w, 1.0);
  EXPECT_EQ(pose.orientation.x, 0.0);
  const sensor_msgs::msg::NavSatFix fix;
  EXPECT_EQ(fix.status.status, sensor_msgs::msg::NavSatStatus::STATUS_UNKNOWN);
  // header 4+4+4+1 (frame_id ""), then status: int8 -2 at payload offset 13.
  const std::vector<std::uint8_t> bytes = agnocast::cdr::serialize(fix);
  EXPECT_EQ(bytes.at(4 + 13), 0xFE);
}

TEST_F(StandardMessage, FixedArrayKeepsItsLength) {
  unique_identifier_msgs::msg::UUID id;
  static_assert(std::tuple_size_v<decltype(id.uuid)> == 16);
  for (std::size_t i = 0; i < id.uuid.size(); ++i) id.uuid[i] = static_cast<std::uint8_t>(i + 1);
  const std::vector<std::uint8_t> bytes = agnocast::cdr::serialize(id);
  ASSERT_EQ(bytes.size(), 4u + 16u);  // no length on the wire
  unique_identifier_msgs::msg::UUID read_back;
  agnocast::cdr::deserialize(bytes, read_back);
  EXPECT_EQ(read_back.uuid, id.uuid);
}

TEST_F(StandardMessage, BoundedSequenceIsCheckedBothWays) {
  shape_msgs::msg::SolidPrimitive box;
  box.type = shape_msgs::msg::SolidPrimitive::BOX;
  box.dimensions = {1.0, 2.0, 3.0};
  std::vector<std::uint8_t> bytes = agnocast::cdr::serialize(box);
  shape_msgs::msg::SolidPrimitive read_back;
  agnocast::cdr::deserialize(bytes, read_back);
  EXPECT_EQ(read_back.dimensions.size(), 3u);
  EXPECT_EQ(read_back.dimensions[shape_msgs::msg::SolidPrimitive::BOX_Z], 3.0);

  box.dimensions.push_back(4.0);
  EXPECT_THROW(agnocast::cdr::serialize(box), agnocast::cdr::Error);
  // The same four values from a peer: count 4 at payload offset 4 (after type and padding).
  bytes.at(4 + 4) = 4;
  const double fourth = 4.0;
  const auto* fourth_bytes = reinterpret_cast<const std::uint8_t*>(&fourth);
  bytes.insert(bytes.begin() + 4 + 8 + 3 * 8, fourth_bytes, fourth_bytes + 8);
  EXPECT_THROW(agnocast::cdr::deserialize(bytes, read_back), agnocast::cdr::Error);
}

TEST_F(StandardMessage, PointCloud2RendersAsTextAndJson) {
  sensor_msgs::msg::PointCloud2 cloud;
  cloud.header.stamp.sec = 12;
  cloud.header.frame_id = "lidar";
  cloud.height = 1;
  cloud.width = 2;
  cloud.fields.push_back({"x", 0, sensor_msgs::msg::PointField::FLOAT32, 1});
  cloud.point_step = 4;
  cloud.row_step = 8;
  cloud.data = {0, 0, 128, 63, 0, 0, 0, 64};
  cloud.is_dense = true;
  const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<decltype(cloud)>());
  EXPECT_EQ(agnocast::render_message_text(&cloud, schema),
            "header:\n"
            "  stamp:\n"
            "    sec: 12\n"
            "    nanosec: 0\n"
            "  frame_id: \"lidar\"\n"
            "height: 1\n"
            "width: 2\n"
            "fields:\n"
            "  - name: \"x\"\n"
            "    offset: 0\n"
            "    datatype: 7\n"
            "    count: 1\n"
            "is_bigendian: false\n"
            "point_step: 4\n"
            "row_step: 8\n"
            "data: [0, 0, 128, 63, 0, 0, 0, 64]\n"
            "is_dense: true\n");
  EXPECT_EQ(agnocast::render_message_json(&cloud, schema, {.show_arrays = false}),
            R"({"header":{"stamp":{"sec":12,"nanosec":0},"frame_id":"lidar"},"height":1,)"
            R"("width":2,"fields":{"length":1},"is_bigendian":false,"point_step":4,)"
            R"("row_step":8,"data":{"length":8},"is_dense":true})");
}

}  // namespace
