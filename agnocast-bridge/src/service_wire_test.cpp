#include "service_wire.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "agnocast/cdr.hpp"
#include "example_interfaces/srv/add_two_ints.hpp"

namespace agnocast_bridge {
namespace {

using AddTwoInts = example_interfaces::srv::AddTwoInts;

// The bytes a ROS 2 client on rmw_cyclonedds_cpp sends for AddTwoInts{a=2,
// b=40} on x86: encapsulation CDR_LE, client 0x0102030405060708 and sequence
// 5 in native (little-endian) order, then a and b.
const std::vector<std::uint8_t> ros2_request = {
    0x00, 0x01, 0x00, 0x00,                          // CDR_LE, no padding
    0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,  // client
    0x05, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // sequence
    0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // a
    0x28, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // b
};

TEST(ServiceWire, TheHeaderGoesBetweenEncapsulationAndMessage) {
  AddTwoInts::Request request;
  request.a = 2;
  request.b = 40;
  EXPECT_EQ(with_request_header({0x0102030405060708, 5}, agnocast::cdr::serialize(request)),
            ros2_request);
}

TEST(ServiceWire, SplittingGivesTheHeaderAndAMessageCdrReads) {
  const auto split = split_request_header(ros2_request);
  ASSERT_TRUE(split);
  EXPECT_EQ(split->header, (DdsRequestHeader{0x0102030405060708, 5}));
  AddTwoInts::Request request;
  agnocast::cdr::deserialize(split->message, request);
  EXPECT_EQ(request.a, 2);
  EXPECT_EQ(request.b, 40);
}

TEST(ServiceWire, ASampleTooShortForAHeaderIsRefused) {
  for (std::size_t size = 0; size < 20; ++size) {
    const std::vector<std::uint8_t> sample(ros2_request.begin(), ros2_request.begin() + size);
    EXPECT_FALSE(split_request_header(sample)) << size;
  }
  const auto empty_message = split_request_header(std::span(ros2_request).first(20));
  ASSERT_TRUE(empty_message);
  EXPECT_EQ(empty_message->message.size(), 4u);
}

TEST(ServiceWire, UserDataHasRmwCycloneDdsForm) {
  std::array<std::uint8_t, 16> id{};
  for (std::size_t i = 0; i < id.size(); ++i) id[i] = static_cast<std::uint8_t>(i * 17);
  EXPECT_EQ(service_user_data("clientid", id),
            "clientid=00.11.22.33.44.55.66.77.88.99.aa.bb.cc.dd.ee.ff;");
}

}  // namespace
}  // namespace agnocast_bridge
