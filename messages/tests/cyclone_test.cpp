// Standard types against Cyclone DDS's idlc-generated serializer for the same
// types written in IDL (standard.idl): a message with every field set, as our
// generated code writes it, is read by Cyclone and written back byte for byte,
// so a DDS peer lays these types out exactly as we do.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <gtest/gtest.h>

#include <agnocast/cdr.hpp>
#include <cstdlib>
#include <diagnostic_msgs/msg/diagnostic_array.hpp>
#include <nav_msgs/msg/occupancy_grid.hpp>
#include <sensor_msgs/msg/battery_state.hpp>
#include <sensor_msgs/msg/nav_sat_fix.hpp>
#include <shape_msgs/msg/solid_primitive.hpp>
#include <std_msgs/msg/char.hpp>
#include <std_msgs/msg/float64_multi_array.hpp>
#include <std_msgs/msg/int8_multi_array.hpp>
#include <trajectory_msgs/msg/joint_trajectory.hpp>
#include <unique_identifier_msgs/msg/uuid.hpp>
#include <visualization_msgs/msg/marker.hpp>

#include "standard.h"
#include "test_support.hpp"

namespace {

constexpr std::uint32_t xcdr1 = 1;  // Cyclone's CDR_ENC_VERSION_1

// Cyclone reads `payload` into a fresh sample and writes it again.
std::vector<std::uint8_t> cyclone_rewrite(std::span<const std::uint8_t> payload,
                                          const dds_topic_descriptor_t& type) {
  dds_istream_t in;
  dds_istream_init(&in, static_cast<std::uint32_t>(payload.size()), payload.data(), xcdr1);
  void* sample = std::calloc(1, type.m_size);
  dds_stream_read(&in, static_cast<char*>(sample), type.m_ops);
  dds_istream_fini(&in);
  dds_ostreamLE_t out;
  dds_ostreamLE_init(&out, 0, xcdr1);
  dds_stream_writeLE(&out, static_cast<const char*>(sample), type.m_ops);
  std::vector<std::uint8_t> bytes(out.x.m_buffer, out.x.m_buffer + out.x.m_index);
  dds_ostreamLE_fini(&out);
  dds_stream_free_sample(sample, type.m_ops);
  std::free(sample);
  return bytes;
}

template <class T>
void expect_cyclone_agrees(const dds_topic_descriptor_t& type) {
  standard_messages_test::install_test_runtime();
  const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<T>());
  for (const std::uint32_t seed : {1U, 2U}) {
    T message;
    agnocast::cdr::deserialize(standard_messages_test::sample_cdr(schema, seed), message);
    const std::vector<std::uint8_t> ours = agnocast::cdr::serialize(message);
    const std::span<const std::uint8_t> payload = std::span(ours).subspan(4);
    EXPECT_EQ(cyclone_rewrite(payload, type),
              std::vector<std::uint8_t>(payload.begin(), payload.end()))
        << agnocast::message_traits<T>::type_name << ", seed " << seed;
  }
}

TEST(StandardAgainstCyclone, SameBytesBothWays) {
  expect_cyclone_agrees<std_msgs::msg::Char>(std_msgs_msg_Char__desc);
  expect_cyclone_agrees<std_msgs::msg::Float64MultiArray>(std_msgs_msg_Float64MultiArray_desc);
  expect_cyclone_agrees<std_msgs::msg::Int8MultiArray>(std_msgs_msg_Int8MultiArray_desc);
  expect_cyclone_agrees<sensor_msgs::msg::NavSatFix>(sensor_msgs_msg_NavSatFix_desc);
  expect_cyclone_agrees<sensor_msgs::msg::BatteryState>(sensor_msgs_msg_BatteryState_desc);
  expect_cyclone_agrees<shape_msgs::msg::SolidPrimitive>(shape_msgs_msg_SolidPrimitive_desc);
  expect_cyclone_agrees<diagnostic_msgs::msg::DiagnosticArray>(
      diagnostic_msgs_msg_DiagnosticArray_desc);
  expect_cyclone_agrees<unique_identifier_msgs::msg::UUID>(unique_identifier_msgs_msg_UUID__desc);
  expect_cyclone_agrees<trajectory_msgs::msg::JointTrajectory>(
      trajectory_msgs_msg_JointTrajectory_desc);
  expect_cyclone_agrees<nav_msgs::msg::OccupancyGrid>(nav_msgs_msg_OccupancyGrid_desc);
  expect_cyclone_agrees<visualization_msgs::msg::Marker>(visualization_msgs_msg_Marker_desc);
}

}  // namespace
