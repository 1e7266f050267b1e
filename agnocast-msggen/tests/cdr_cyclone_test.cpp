// The XCDR1 bytes of generated messages against those of Cyclone DDS's
// idlc-generated C serializer for the same types (tests/idl/golden.idl), and
// round trips in both directions.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <gtest/gtest.h>

#include <agnocast/cdr.hpp>
#include <cstdlib>
#include <cstring>
#include <golden_msgs/msg/wheel.hpp>
#include <sensor_msgs/msg/imu.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>

#include "golden.h"
#include "kernel/runtime.hpp"

namespace {

constexpr std::uint32_t xcdr1 = 1;  // Cyclone's CDR_ENC_VERSION_1

std::vector<std::uint8_t> cyclone_write(const void* sample, const dds_topic_descriptor_t& type) {
  dds_ostreamLE_t stream;
  dds_ostreamLE_init(&stream, 0, xcdr1);
  dds_stream_writeLE(&stream, static_cast<const char*>(sample), type.m_ops);
  std::vector<std::uint8_t> bytes(stream.x.m_buffer, stream.x.m_buffer + stream.x.m_index);
  dds_ostreamLE_fini(&stream);
  return bytes;
}

// Cyclone reads `payload` into a fresh sample and writes it again.
std::vector<std::uint8_t> cyclone_rewrite(std::span<const std::uint8_t> payload,
                                          const dds_topic_descriptor_t& type) {
  dds_istream_t stream;
  dds_istream_init(&stream, static_cast<std::uint32_t>(payload.size()), payload.data(), xcdr1);
  void* sample = std::calloc(1, type.m_size);
  dds_stream_read(&stream, static_cast<char*>(sample), type.m_ops);
  std::vector<std::uint8_t> bytes = cyclone_write(sample, type);
  dds_stream_free_sample(sample, type.m_ops);
  std::free(sample);
  dds_istream_fini(&stream);
  return bytes;
}

std::span<const std::uint8_t> payload_of(const std::vector<std::uint8_t>& bytes) {
  return std::span(bytes).subspan(4);
}

class CdrAgainstCyclone : public ::testing::Test {
 protected:
  static constexpr std::size_t pool_size = 4 << 20;
  void SetUp() override {
    region_ = new (std::align_val_t{4096}) std::byte[pool_size];
    agnocast::detail::Runtime::install_for_testing(region_, pool_size);
  }
  std::byte* region_ = nullptr;  // left to the leaked test runtime, like every test pool

  // Ours equal Cyclone's; each side reads the other's bytes and writes them back unchanged.
  template <class Message>
  void expect_same_bytes(const Message& message, const void* sample,
                         const dds_topic_descriptor_t& type) {
    const std::vector<std::uint8_t> ours = agnocast::cdr::serialize(message);
    ASSERT_GE(ours.size(), 4u);
    EXPECT_EQ(std::vector<std::uint8_t>(ours.begin(), ours.begin() + 4),
              (std::vector<std::uint8_t>{0x00, 0x01, 0x00, 0x00}));
    const std::vector<std::uint8_t> theirs = cyclone_write(sample, type);
    EXPECT_EQ(std::vector<std::uint8_t>(payload_of(ours).begin(), payload_of(ours).end()), theirs);
    EXPECT_EQ(cyclone_rewrite(payload_of(ours), type), theirs);

    std::vector<std::uint8_t> framed(agnocast::cdr::encapsulation_header.begin(),
                                     agnocast::cdr::encapsulation_header.end());
    framed.insert(framed.end(), theirs.begin(), theirs.end());
    Message read_back;
    agnocast::cdr::deserialize(framed, read_back);
    EXPECT_EQ(agnocast::cdr::serialize(read_back), ours);
  }
};

TEST_F(CdrAgainstCyclone, NestedBoundedAndFixedContainers) {
  golden_msgs::msg::Wheel wheel;
  wheel.header.stamp.sec = -5;
  wheel.header.stamp.nanosec = 123;
  wheel.header.frame_id = "base_link";
  wheel.tire.pressure_kpa = 230;
  wheel.tire.brand = "Michelin";
  wheel.name = "front_left";
  wheel.radius = 0.31;
  wheel.ticks = {7, -8, 9};
  wheel.speeds = {1.5F, -2.25F, 3.0F};
  wheel.tags = {"a", "bb", "ccc"};
  wheel.flags = {1, 0, 1};
  wheel.enabled = false;
  wheel.spares[0] = {200, "x"};
  wheel.spares[1] = {210, ""};
  wheel.axes = {{1.0, 2.0, 3.0}};
  wheel.status = 0xAB;
  wheel.code = 'Z';
  wheel.odometer = (1ULL << 40) + 3;

  float speeds[] = {1.5F, -2.25F, 3.0F};
  char tags[][9] = {"a", "bb", "ccc"};
  bool flags[] = {true, false, true};
  geometry_msgs_msg_Vector3 axes[] = {{1.0, 2.0, 3.0}};
  golden_msgs_msg_Wheel sample{};
  sample.header.stamp = {-5, 123};
  sample.header.frame_id = const_cast<char*>("base_link");
  sample.tire = {230, const_cast<char*>("Michelin")};
  std::strcpy(sample.name, "front_left");
  sample.radius = 0.31;
  sample.ticks[0] = 7;
  sample.ticks[1] = -8;
  sample.ticks[2] = 9;
  sample.speeds = {3, 3, speeds, false};
  sample.tags = {3, 3, tags, false};
  sample.flags = {3, 3, flags, false};
  sample.enabled = false;
  sample.spares[0] = {200, const_cast<char*>("x")};
  sample.spares[1] = {210, const_cast<char*>("")};
  sample.axes = {1, 1, axes, false};
  sample.status = 0xAB;
  sample.code = 'Z';
  sample.odometer = (1ULL << 40) + 3;

  expect_same_bytes(wheel, &sample, golden_msgs_msg_Wheel_desc);
}

TEST_F(CdrAgainstCyclone, EmptySequencesAndStrings) {
  golden_msgs::msg::Wheel wheel;  // every sequence empty, strings empty but `name`
  wheel.tags.clear();
  wheel.status = 1;
  golden_msgs_msg_Wheel sample{};
  sample.header.frame_id = const_cast<char*>("");
  sample.tire = {220, const_cast<char*>("")};
  std::strcpy(sample.name, "wheel");
  sample.radius = 0.3;
  sample.ticks[0] = 1;
  sample.ticks[1] = -2;
  sample.ticks[2] = 3;
  sample.enabled = true;
  for (auto& spare : sample.spares) spare = {220, const_cast<char*>("")};
  sample.status = 1;
  sample.code = 65;
  sample.odometer = UINT64_MAX;
  expect_same_bytes(wheel, &sample, golden_msgs_msg_Wheel_desc);
}

TEST_F(CdrAgainstCyclone, PointCloud2WithNestedSequenceOfStructs) {
  sensor_msgs::msg::PointCloud2 cloud;
  cloud.header.stamp = {1700000000, 5};
  cloud.header.frame_id = "lidar";
  cloud.height = 1;
  cloud.width = 2;
  cloud.fields.push_back({"x", 0, sensor_msgs::msg::PointField::FLOAT32, 1});
  cloud.fields.push_back({"intensity", 4, sensor_msgs::msg::PointField::FLOAT32, 1});
  cloud.point_step = 8;
  cloud.row_step = 16;
  for (std::uint8_t i = 0; i < 13; ++i) cloud.data.push_back(static_cast<std::uint8_t>(i * 19));
  cloud.is_dense = true;

  sensor_msgs_msg_PointField fields[] = {{const_cast<char*>("x"), 0, 7, 1},
                                         {const_cast<char*>("intensity"), 4, 7, 1}};
  std::vector<std::uint8_t> data(cloud.data.begin(), cloud.data.end());
  sensor_msgs_msg_PointCloud2 sample{};
  sample.header.stamp = {1700000000, 5};
  sample.header.frame_id = const_cast<char*>("lidar");
  sample.height = 1;
  sample.width = 2;
  sample.fields = {2, 2, fields, false};
  sample.point_step = 8;
  sample.row_step = 16;
  sample.data = {13, 13, data.data(), false};
  sample.is_dense = true;

  expect_same_bytes(cloud, &sample, sensor_msgs_msg_PointCloud2_desc);
}

TEST_F(CdrAgainstCyclone, ImuWithFixedArraysAfterAString) {
  sensor_msgs::msg::Imu imu;
  imu.header.frame_id = "imu";  // 4 bytes with the NUL, so the doubles after it need padding
  imu.orientation.w = 0.5;
  sensor_msgs_msg_Imu sample{};
  sample.header.frame_id = const_cast<char*>("imu");
  sample.orientation = {0.0, 0.0, 0.0, 0.5};
  for (int i = 0; i < 9; ++i) {
    imu.orientation_covariance[i] = sample.orientation_covariance[i] = i * 0.5;
    imu.angular_velocity_covariance[i] = sample.angular_velocity_covariance[i] = -i;
    imu.linear_acceleration_covariance[i] = sample.linear_acceleration_covariance[i] = i * i;
  }
  imu.linear_acceleration.z = 9.81;
  sample.linear_acceleration.z = 9.81;
  expect_same_bytes(imu, &sample, sensor_msgs_msg_Imu_desc);
}

TEST_F(CdrAgainstCyclone, BoundsAreEnforcedBothWays) {
  golden_msgs::msg::Wheel wheel;
  wheel.name = "a name longer than 16";
  EXPECT_THROW(agnocast::cdr::serialize(wheel), agnocast::cdr::Error);
  wheel.name = "ok";
  wheel.axes.resize(4);
  EXPECT_THROW(agnocast::cdr::serialize(wheel), agnocast::cdr::Error);
  wheel.axes.resize(3);
  std::vector<std::uint8_t> bytes = agnocast::cdr::serialize(wheel);
  bytes.resize(bytes.size() - 3);
  golden_msgs::msg::Wheel truncated;
  EXPECT_THROW(agnocast::cdr::deserialize(bytes, truncated), agnocast::cdr::Error);
}

}  // namespace
