// The shipped standard set: every type compiles, has a valid schema within the
// kernel's bound, round-trips through XCDR1 and renders from its schema alone.
#include <gtest/gtest.h>

#include <agnocast/message_render.hpp>
#include <builtin_interfaces/msg/time.hpp>
#include <geometry_msgs/msg/point.hpp>
#include <geometry_msgs/msg/pose.hpp>
#include <geometry_msgs/msg/pose_stamped.hpp>
#include <geometry_msgs/msg/quaternion.hpp>
#include <geometry_msgs/msg/transform.hpp>
#include <geometry_msgs/msg/transform_stamped.hpp>
#include <geometry_msgs/msg/twist.hpp>
#include <geometry_msgs/msg/vector3.hpp>
#include <sensor_msgs/msg/image.hpp>
#include <sensor_msgs/msg/imu.hpp>
#include <sensor_msgs/msg/laser_scan.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <sensor_msgs/msg/point_field.hpp>
#include <set>
#include <std_msgs/msg/header.hpp>

#include "runtime.hpp"

namespace {

template <class T>
class StandardMessage : public ::testing::Test {
 protected:
  void SetUp() override {
    static constexpr std::size_t pool_size = 1 << 20;
    // Left to the leaked test runtime, like every test pool.
    auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
    agnocast::detail::Runtime::install_for_testing(region, pool_size);
  }
};

using StandardTypes =
    ::testing::Types<builtin_interfaces::msg::Time, std_msgs::msg::Header,
                     geometry_msgs::msg::Vector3, geometry_msgs::msg::Point,
                     geometry_msgs::msg::Quaternion, geometry_msgs::msg::Pose,
                     geometry_msgs::msg::PoseStamped, geometry_msgs::msg::Twist,
                     geometry_msgs::msg::Transform, geometry_msgs::msg::TransformStamped,
                     sensor_msgs::msg::PointField, sensor_msgs::msg::PointCloud2,
                     sensor_msgs::msg::Image, sensor_msgs::msg::Imu, sensor_msgs::msg::LaserScan>;
TYPED_TEST_SUITE(StandardMessage, StandardTypes);

TYPED_TEST(StandardMessage, SchemaIsValidAndFitsTheKernel) {
  const auto blob = agnocast::schema_of<TypeParam>();
  EXPECT_LE(blob.size(), agnocast::schema_max_bytes);
  const agnocast::Schema schema = agnocast::parse_schema(blob);
  EXPECT_EQ(schema.types[0].name, agnocast::message_traits<TypeParam>::type_name);
  EXPECT_EQ(schema.types[0].hash, agnocast::message_traits<TypeParam>::type_hash);
  EXPECT_EQ(schema.types[0].fields.size(), agnocast::message_traits<TypeParam>::fields.size());
}

TYPED_TEST(StandardMessage, RoundTripsThroughCdr) {
  const TypeParam original;
  const std::vector<std::uint8_t> bytes = agnocast::cdr::serialize(original);
  TypeParam read_back;
  agnocast::cdr::deserialize(bytes, read_back);
  EXPECT_EQ(agnocast::cdr::serialize(read_back), bytes);
}

TYPED_TEST(StandardMessage, RendersFromItsSchema) {
  const TypeParam message;
  const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<TypeParam>());
  const std::string json = agnocast::render_message_json(&message, schema);
  EXPECT_EQ(json.front(), '{');
  EXPECT_EQ(json.back(), '}');
  EXPECT_EQ(json.find('\n'), std::string::npos);
  EXPECT_NE(agnocast::render_message_text(&message, schema).find(schema.types[0].fields[0].name),
            std::string::npos);
}

TEST(StandardSet, HashesAreDistinct) {
  const std::set<std::uint64_t> hashes{
      agnocast::message_traits<geometry_msgs::msg::Vector3>::type_hash,
      agnocast::message_traits<geometry_msgs::msg::Point>::type_hash,
      agnocast::message_traits<geometry_msgs::msg::Pose>::type_hash,
      agnocast::message_traits<geometry_msgs::msg::Transform>::type_hash,
      agnocast::message_traits<sensor_msgs::msg::PointCloud2>::type_hash,
      agnocast::message_traits<sensor_msgs::msg::Image>::type_hash};
  EXPECT_EQ(hashes.size(), 6u);  // Vector3 and Point share a layout, not a name
}

class PointCloud2Render : public StandardMessage<sensor_msgs::msg::PointCloud2> {};

TEST_F(PointCloud2Render, TextAndJson) {
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
