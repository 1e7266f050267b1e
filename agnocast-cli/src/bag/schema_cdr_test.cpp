// bag record writes messages from their schema alone: the bytes must be the
// ones the generated types' cdr::serialize() writes (and the bridge sends),
// and the .msg text must describe them as rosbag2 does.
#include <gtest/gtest.h>

#include <agnocast/detail/message.hpp>
#include <agnocast/schema_cdr.hpp>
#include <agnocast/schema_definition.hpp>
#include <algorithm>
#include <fstream>
#include <geometry_msgs/msg/transform_stamped.hpp>
#include <memory>
#include <sensor_msgs/msg/imu.hpp>
#include <sensor_msgs/msg/laser_scan.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "kernel/runtime.hpp"
#include "standard_types.hpp"

namespace {

constexpr std::size_t pool_size = 1 << 22;

std::span<const std::byte> test_pool() {
  // Left to the leaked test runtime, like every test pool.
  static std::byte* region = [] {
    auto* bytes = new (std::align_val_t{4096}) std::byte[pool_size];
    agnocast::detail::Runtime::install_for_testing(bytes, pool_size);
    return bytes;
  }();
  return {region, pool_size};
}

template <class T>
std::vector<std::uint8_t> from_schema(const T& message, const agnocast::SchemaCdrOptions& options) {
  const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<T>());
  std::vector<std::uint8_t> out{9, 9, 9};  // replaced, not appended to
  agnocast::serialize_with_schema(&message, schema, out, options);
  return out;
}

sensor_msgs::msg::PointCloud2 sample_cloud() {
  sensor_msgs::msg::PointCloud2 cloud;
  cloud.header.stamp.sec = 1700000000;
  cloud.header.stamp.nanosec = 123456789;
  cloud.header.frame_id = "lidar_top";
  cloud.height = 1;
  cloud.width = 1000;
  for (const char* name : {"x", "y", "z", "intensity"}) {
    sensor_msgs::msg::PointField field;
    field.name = name;
    field.offset = static_cast<std::uint32_t>(4 * cloud.fields.size());
    field.datatype = sensor_msgs::msg::PointField::FLOAT32;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.is_bigendian = false;
  cloud.point_step = 16;
  cloud.row_step = 16000;
  cloud.data.resize(16000);
  for (std::size_t i = 0; i < cloud.data.size(); ++i) {
    cloud.data[i] = static_cast<std::uint8_t>(i * 7);
  }
  cloud.is_dense = true;
  return cloud;
}

TEST(SchemaCdr, PointCloud2IsByteEqualToTheGeneratedSerializer) {
  test_pool();
  const auto cloud = sample_cloud();
  EXPECT_EQ(from_schema(cloud, {}), agnocast::cdr::serialize(cloud));
}

TEST(SchemaCdr, OtherStandardTypesAreByteEqual) {
  test_pool();
  sensor_msgs::msg::Imu imu;
  imu.header.frame_id = "imu";
  imu.orientation.w = 1.0;
  imu.angular_velocity.z = -0.25;
  imu.orientation_covariance[4] = 3.5;
  EXPECT_EQ(from_schema(imu, {}), agnocast::cdr::serialize(imu));

  sensor_msgs::msg::LaserScan scan;
  scan.angle_min = -1.5f;
  scan.ranges = {1.0f, 2.0f, 3.5f};
  scan.intensities = {};
  EXPECT_EQ(from_schema(scan, {}), agnocast::cdr::serialize(scan));

  geometry_msgs::msg::TransformStamped transform;
  transform.child_frame_id = "";  // an empty string is still a length and a NUL
  transform.transform.translation.x = 2.0;
  EXPECT_EQ(from_schema(transform, {}), agnocast::cdr::serialize(transform));
}

TEST(SchemaCdr, CheckedReadsOnlyThePool) {
  const auto pool = test_pool();
  // A cloud built in the pool, as a publisher's loan is.
  auto loan = agnocast::detail::allocate_message(sizeof(sensor_msgs::msg::PointCloud2),
                                                 alignof(sensor_msgs::msg::PointCloud2), nullptr);
  auto* cloud = new (loan) sensor_msgs::msg::PointCloud2(sample_cloud());
  EXPECT_EQ(from_schema(*cloud, {.readable = pool}), agnocast::cdr::serialize(*cloud));
  // The same message judged against a range that holds only the message itself:
  // its containers lie outside, which is an error, not a read.
  const std::span<const std::byte> only_message(reinterpret_cast<const std::byte*>(cloud),
                                                sizeof(*cloud));
  try {
    from_schema(*cloud, {.readable = only_message});
    ADD_FAILURE() << "containers outside the readable range were written";
  } catch (const agnocast::cdr::Error& error) {
    EXPECT_NE(std::string(error.what()).find("'fields'"), std::string::npos) << error.what();
  }
  // A message on the stack is outside the pool altogether.
  const auto outside = sample_cloud();
  EXPECT_THROW(from_schema(outside, {.readable = pool}), agnocast::cdr::Error);
  // The output bound holds.
  EXPECT_THROW(from_schema(*cloud, {.readable = pool, .max_bytes = 1000}), agnocast::cdr::Error);
  std::destroy_at(cloud);
  agnocast::detail::free_message_memory(loan);
}

// A standard .msg file as it is in the source tree.
std::string msg_file(const std::string& package, const std::string& name) {
  std::ifstream file(std::string(MESSAGES_DIR) + "/" + package + "/msg/" + name + ".msg");
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// A type declared in C++ has no .msg text: its fields are written from the schema.
TEST(SchemaCdr, Ros2msgDefinitionListsEveryTypeOnceInRosbag2Layout) {
  agnocast::Schema schema =
      agnocast::parse_schema(agnocast::schema_of<sensor_msgs::msg::PointCloud2>());
  for (agnocast::SchemaType& type : schema.types) type.definition.clear();
  const std::string separator(80, '=');
  const std::string expected =
      "std_msgs/Header header\n"
      "uint32 height\n"
      "uint32 width\n"
      "sensor_msgs/PointField[] fields\n"
      "bool is_bigendian\n"
      "uint32 point_step\n"
      "uint32 row_step\n"
      "uint8[] data\n"
      "bool is_dense\n" +
      separator +
      "\nMSG: std_msgs/Header\n"
      "builtin_interfaces/Time stamp\n"
      "string frame_id\n" +
      separator +
      "\nMSG: builtin_interfaces/Time\n"
      "int32 sec\n"
      "uint32 nanosec\n" +
      separator +
      "\nMSG: sensor_msgs/PointField\n"
      "string name\n"
      "uint32 offset\n"
      "uint8 datatype\n"
      "uint32 count\n";
  EXPECT_EQ(agnocast::ros2msg_definition(schema), expected);
  EXPECT_EQ(agnocast::ros2msg_type_name("sensor_msgs/msg/PointCloud2"), "sensor_msgs/PointCloud2");
  EXPECT_EQ(agnocast::ros2msg_type_name("odd"), "odd");
}

TEST(SchemaCdr, FixedArraysHaveTheirLengthInTheDefinition) {
  agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<sensor_msgs::msg::Imu>());
  for (agnocast::SchemaType& type : schema.types) type.definition.clear();
  const std::string text = agnocast::ros2msg_definition(schema);
  EXPECT_NE(text.find("float64[9] orientation_covariance\n"), std::string::npos) << text;
  EXPECT_NE(text.find("MSG: geometry_msgs/Quaternion\n"), std::string::npos) << text;
  // Vector3 is used twice, listed once.
  EXPECT_EQ(text.find("MSG: geometry_msgs/Vector3\n"), text.rfind("MSG: geometry_msgs/Vector3\n"));
}

// The schema carries each type's .msg file as agnocast-msggen read it, so
// the definition is the whole file, constants and comments included, as
// rosbag2 writes it.
TEST(SchemaCdr, StandardTypesKeepTheirConstantsAndComments) {
  const agnocast::Schema schema =
      agnocast::parse_schema(agnocast::schema_of<sensor_msgs::msg::PointCloud2>());
  const std::string text = agnocast::ros2msg_definition(schema);
  const std::string point_field = msg_file("sensor_msgs", "PointField");
  ASSERT_FALSE(point_field.empty());
  EXPECT_NE(text.find("uint8 FLOAT32=7\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nMSG: sensor_msgs/PointField\n" + point_field), std::string::npos) << text;
  const std::string cloud = msg_file("sensor_msgs", "PointCloud2");
  ASSERT_FALSE(cloud.empty());
  EXPECT_EQ(text.rfind(cloud, 0), 0U) << "the root's own text comes first";
  EXPECT_NE(text.find("\nMSG: std_msgs/Header\n" + msg_file("std_msgs", "Header")),
            std::string::npos);
  EXPECT_EQ(schema.types[0].definition, cloud);
}

// bag play lays out a foreign file's standard types as the generated
// headers do: the same name, hash and schema a compiled subscriber registers.
TEST(SchemaCdr, StandardTypesAreKnownByNameAsTheirHeadersDeclareThem) {
  const agnocast::detail::MessageType expected =
      agnocast::detail::message_type_of<sensor_msgs::msg::PointCloud2>();
  const agnocast::detail::MessageType* known =
      agnocast::standard_message_type("sensor_msgs/msg/PointCloud2");
  ASSERT_NE(known, nullptr);
  EXPECT_EQ(known->name, expected.name);
  EXPECT_EQ(known->hash, expected.hash);
  EXPECT_TRUE(std::equal(known->schema.begin(), known->schema.end(), expected.schema.begin(),
                         expected.schema.end()));
  EXPECT_NE(agnocast::standard_message_type("geometry_msgs/msg/TransformStamped"), nullptr);
  EXPECT_NE(agnocast::standard_message_type("tf2_msgs/msg/TFMessage"), nullptr);
  EXPECT_EQ(agnocast::standard_message_type("robot/msg/Scan"), nullptr);
}

TEST(SchemaCdr, FieldNamesOfAMsgTextSkipConstantsAndComments) {
  EXPECT_EQ(agnocast::msg_text_field_names("# a comment\n"
                                           "uint8 A=1\n"
                                           "int32 B = -2  # spaced\n"
                                           "string C=\"x#y\"\n"
                                           "\n"
                                           "string<=8 name  # bounded\n"
                                           "float64[3] values\n"
                                           "int32 count 5\n"),
            (std::vector<std::string>{"name", "values", "count"}));
}

// A text whose fields are not the schema's (another process's schema lies)
// is not written: that type's fields come from the schema.
TEST(SchemaCdr, ATextWithOtherFieldsIsWrittenFromTheSchema) {
  agnocast::Schema schema =
      agnocast::parse_schema(agnocast::schema_of<sensor_msgs::msg::PointCloud2>());
  const std::string truthful = agnocast::ros2msg_definition(schema);
  for (agnocast::SchemaType& type : schema.types) {
    if (type.name == "sensor_msgs/msg/PointField")
      type.definition = "# not the real one\nint32 only\n";
  }
  const std::string text = agnocast::ros2msg_definition(schema);
  EXPECT_EQ(text.find("int32 only"), std::string::npos) << text;
  EXPECT_NE(text.find("\nMSG: sensor_msgs/PointField\nstring name\nuint32 offset\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text, truthful);
}

}  // namespace
