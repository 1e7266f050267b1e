// The generated golden service and the standard services compiled: names,
// Request/Response, traits, hashes, XCDR1 and each part's definition.
#include <gtest/gtest.h>

#include <agnocast/service_traits.hpp>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <fstream>
#include <golden_msgs/srv/steer.hpp>
#include <sstream>
#include <std_srvs/srv/empty.hpp>
#include <std_srvs/srv/set_bool.hpp>
#include <std_srvs/srv/trigger.hpp>
#include <type_traits>

#include "kernel/runtime.hpp"

namespace {

using agnocast::message_traits;
using agnocast::service_traits;
using golden_msgs::srv::Steer;

static_assert(agnocast::ServiceType<Steer>);
static_assert(agnocast::ServiceType<std_srvs::srv::Empty>);
static_assert(agnocast::ServiceType<std_srvs::srv::Trigger>);
static_assert(agnocast::ServiceType<std_srvs::srv::SetBool>);
static_assert(agnocast::ServiceType<example_interfaces::srv::AddTwoInts>);
// A message is not a service, nor is a service's part.
static_assert(!agnocast::ServiceType<golden_msgs::msg::Tire>);
static_assert(!agnocast::ServiceType<Steer::Request>);

class GeneratedService : public ::testing::Test {
 protected:
  void SetUp() override {
    static constexpr std::size_t pool_size = 1 << 20;
    region_ = new (std::align_val_t{4096}) std::byte[pool_size];
    agnocast::detail::Runtime::install_for_testing(region_, pool_size);
  }
  std::byte* region_ = nullptr;  // left to the leaked test runtime, like every test pool
};

std::string read_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

TEST(GeneratedServiceType, NamesFollowRos2) {
  static_assert(std::is_same_v<Steer::Request, golden_msgs::srv::Steer_Request>);
  static_assert(std::is_same_v<Steer::Response, golden_msgs::srv::Steer_Response>);
  static_assert(agnocast::DeclaredMessage<Steer::Request>);
  static_assert(agnocast::Publishable<Steer::Response>);
  EXPECT_EQ(service_traits<Steer>::type_name, "golden_msgs/srv/Steer");
  EXPECT_EQ(message_traits<Steer::Request>::type_name, "golden_msgs/srv/Steer_Request");
  EXPECT_EQ(message_traits<Steer::Response>::type_name, "golden_msgs/srv/Steer_Response");
  EXPECT_EQ(service_traits<std_srvs::srv::SetBool>::type_name, "std_srvs/srv/SetBool");
  EXPECT_EQ(message_traits<std_srvs::srv::SetBool::Request>::type_name,
            "std_srvs/srv/SetBool_Request");
  EXPECT_EQ(service_traits<example_interfaces::srv::AddTwoInts>::type_name,
            "example_interfaces/srv/AddTwoInts");
  EXPECT_EQ(message_traits<example_interfaces::srv::AddTwoInts::Response>::type_name,
            "example_interfaces/srv/AddTwoInts_Response");
}

TEST(GeneratedServiceType, ConstantsAndFieldsOfEachPart) {
  static_assert(Steer::Request::MAX_ANGLE == 0.6F);
  static_assert(Steer::Response::REFUSED == 1);
  static_assert(std::is_same_v<decltype(Steer::Request::tire), golden_msgs::msg::Tire>);
  static_assert(std::is_same_v<decltype(Steer::Response::header), std_msgs::msg::Header>);
  const auto& fields = message_traits<Steer::Request>::fields;
  ASSERT_EQ(fields.size(), 3u);
  EXPECT_EQ(fields[1].name, "reason");
  EXPECT_EQ(fields[1].string_bound, 16u);
  EXPECT_EQ(fields[2].nested, &message_traits<golden_msgs::msg::Tire>::descriptor);
  EXPECT_EQ(message_traits<Steer::Response>::fields[2].sequence_bound, 2u);
  // An empty part has ROS 2's placeholder byte.
  EXPECT_EQ(message_traits<std_srvs::srv::Empty::Request>::fields.size(), 1u);
  EXPECT_EQ(message_traits<std_srvs::srv::Empty::Response>::fields[0].name,
            "structure_needs_at_least_one_member");
}

TEST(GeneratedServiceType, HashesOfTheParts) {
  EXPECT_EQ(service_traits<Steer>::request_type_hash, message_traits<Steer::Request>::type_hash);
  EXPECT_EQ(service_traits<Steer>::response_type_hash, message_traits<Steer::Response>::type_hash);
  EXPECT_NE(service_traits<Steer>::request_type_hash, service_traits<Steer>::response_type_hash);
  // Empty's two parts have one layout, not one name.
  using Empty = std_srvs::srv::Empty;
  EXPECT_NE(service_traits<Empty>::request_type_hash, service_traits<Empty>::response_type_hash);
  // Trigger and SetBool answer alike; the names keep them apart.
  EXPECT_NE(service_traits<std_srvs::srv::Trigger>::response_type_hash,
            service_traits<std_srvs::srv::SetBool>::response_type_hash);
}

// Each part carries its own lines of the .srv file, byte for byte.
TEST(GeneratedServiceType, DefinitionOfEachPartIsItsPartOfTheFile) {
  const std::string text = read_file(std::string(GOLDEN_SRVS_DIR) + "/Steer.srv");
  const std::size_t separator = text.find("\n---\n");
  ASSERT_NE(separator, std::string::npos);
  EXPECT_EQ(message_traits<Steer::Request>::definition, text.substr(0, separator + 1));
  EXPECT_EQ(message_traits<Steer::Response>::definition, text.substr(separator + 5));
  EXPECT_EQ(message_traits<Steer::Request>::descriptor.definition,
            message_traits<Steer::Request>::definition);
  EXPECT_EQ(message_traits<example_interfaces::srv::AddTwoInts::Response>::definition,
            "int64 sum\n");
  EXPECT_EQ(message_traits<std_srvs::srv::Empty::Request>::definition, "");
}

TEST_F(GeneratedService, RequestAndResponseRoundTrip) {
  Steer::Request request;
  EXPECT_EQ(request.reason, "manual");
  EXPECT_EQ(request.tire.pressure_kpa, 220);
  request.angle = -0.25F;
  request.reason = "avoid";
  request.tire.brand = "acme";
  const std::vector<std::uint8_t> request_bytes = agnocast::cdr::serialize(request);
  Steer::Request request_back;
  agnocast::cdr::deserialize(request_bytes, request_back);
  EXPECT_EQ(request_back.angle, -0.25F);
  EXPECT_EQ(request_back.reason, "avoid");
  EXPECT_EQ(request_back.tire.brand, "acme");
  EXPECT_EQ(agnocast::cdr::serialize(request_back), request_bytes);

  Steer::Response response;
  response.status = Steer::Response::REFUSED;
  response.angle = 0.5F;
  response.notes.emplace_back("limit");
  response.header.frame_id = "base";
  response.header.stamp.sec = 7;
  const std::vector<std::uint8_t> response_bytes = agnocast::cdr::serialize(response);
  Steer::Response response_back;
  agnocast::cdr::deserialize(response_bytes, response_back);
  EXPECT_EQ(response_back.status, Steer::Response::REFUSED);
  EXPECT_EQ(response_back.angle, 0.5F);
  ASSERT_EQ(response_back.notes.size(), 1u);
  EXPECT_EQ(response_back.notes[0], "limit");
  EXPECT_EQ(response_back.header.frame_id, "base");
  EXPECT_EQ(response_back.header.stamp.sec, 7);
  EXPECT_EQ(agnocast::cdr::serialize(response_back), response_bytes);

  // The bounds of each part hold both ways.
  request.reason = "seventeen letters";
  EXPECT_THROW(agnocast::cdr::serialize(request), agnocast::cdr::Error);
  response.notes.emplace_back("b");
  response.notes.emplace_back("c");
  EXPECT_THROW(agnocast::cdr::serialize(response), agnocast::cdr::Error);
}

TEST_F(GeneratedService, StandardServicesRoundTrip) {
  std_srvs::srv::SetBool::Request enable;
  enable.data = true;
  std_srvs::srv::SetBool::Request enable_back;
  agnocast::cdr::deserialize(agnocast::cdr::serialize(enable), enable_back);
  EXPECT_TRUE(enable_back.data);

  std_srvs::srv::Trigger::Response done;
  done.success = true;
  done.message = "done";
  std_srvs::srv::Trigger::Response done_back;
  agnocast::cdr::deserialize(agnocast::cdr::serialize(done), done_back);
  EXPECT_TRUE(done_back.success);
  EXPECT_EQ(done_back.message, "done");

  example_interfaces::srv::AddTwoInts::Request sum;
  sum.a = 2;
  sum.b = -5;
  example_interfaces::srv::AddTwoInts::Request sum_back;
  agnocast::cdr::deserialize(agnocast::cdr::serialize(sum), sum_back);
  EXPECT_EQ(sum_back.a, 2);
  EXPECT_EQ(sum_back.b, -5);
}

}  // namespace
