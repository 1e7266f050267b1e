// The standard services (std_srvs, example_interfaces): type names, the
// schemas of their parts, and the XCDR1 bytes a ROS 2 peer sends for them.
#include <gtest/gtest.h>

#include <agnocast/cdr.hpp>
#include <agnocast/schema.hpp>
#include <agnocast/service_traits.hpp>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <std_srvs/srv/empty.hpp>
#include <std_srvs/srv/set_bool.hpp>
#include <std_srvs/srv/trigger.hpp>
#include <string_view>
#include <vector>

#include "test_support.hpp"

namespace {

using standard_messages_test::install_test_runtime;

class StandardService : public ::testing::Test {
 protected:
  void SetUp() override { install_test_runtime(); }
};

template <class... Services>
struct ServiceList {};

template <class... Services, class F>
void for_each_part(ServiceList<Services...>, F&& check) {
  (check.template operator()<typename Services::Request>(), ...);
  (check.template operator()<typename Services::Response>(), ...);
}

using Services = ServiceList<std_srvs::srv::Empty, std_srvs::srv::Trigger, std_srvs::srv::SetBool,
                             example_interfaces::srv::AddTwoInts>;

TEST(StandardServiceType, NamesAreRos2s) {
  EXPECT_EQ(agnocast::service_traits<std_srvs::srv::Empty>::type_name, "std_srvs/srv/Empty");
  EXPECT_EQ(agnocast::service_traits<std_srvs::srv::Trigger>::type_name, "std_srvs/srv/Trigger");
  EXPECT_EQ(agnocast::service_traits<std_srvs::srv::SetBool>::type_name, "std_srvs/srv/SetBool");
  EXPECT_EQ(agnocast::service_traits<example_interfaces::srv::AddTwoInts>::type_name,
            "example_interfaces/srv/AddTwoInts");
  EXPECT_EQ(agnocast::message_traits<std_srvs::srv::Trigger::Request>::type_name,
            "std_srvs/srv/Trigger_Request");
  EXPECT_EQ(agnocast::message_traits<example_interfaces::srv::AddTwoInts::Response>::type_name,
            "example_interfaces/srv/AddTwoInts_Response");
}

template <class T>
std::vector<std::string_view> field_names() {
  std::vector<std::string_view> names;
  for (const auto& field : agnocast::message_traits<T>::fields) names.emplace_back(field.name);
  return names;
}

// Field names and order of ROS 2's .srv files (types: the bytes below).
TEST(StandardServiceType, FieldsAreRos2s) {
  using Names = std::vector<std::string_view>;
  const Names placeholder{"structure_needs_at_least_one_member"};
  EXPECT_EQ(field_names<std_srvs::srv::Empty::Request>(), placeholder);
  EXPECT_EQ(field_names<std_srvs::srv::Empty::Response>(), placeholder);
  EXPECT_EQ(field_names<std_srvs::srv::Trigger::Request>(), placeholder);
  EXPECT_EQ(field_names<std_srvs::srv::Trigger::Response>(), (Names{"success", "message"}));
  EXPECT_EQ(field_names<std_srvs::srv::SetBool::Request>(), (Names{"data"}));
  EXPECT_EQ(field_names<std_srvs::srv::SetBool::Response>(), (Names{"success", "message"}));
  EXPECT_EQ(field_names<example_interfaces::srv::AddTwoInts::Request>(), (Names{"a", "b"}));
  EXPECT_EQ(field_names<example_interfaces::srv::AddTwoInts::Response>(), (Names{"sum"}));
}

TEST_F(StandardService, SchemasOfThePartsAreValid) {
  for_each_part(Services{}, []<class T>() {
    const auto blob = agnocast::schema_of<T>();
    EXPECT_LE(blob.size(), agnocast::schema_max_bytes);
    const agnocast::Schema schema = agnocast::parse_schema(blob);
    EXPECT_EQ(schema.types[0].name, agnocast::message_traits<T>::type_name);
    EXPECT_EQ(schema.types[0].hash, agnocast::message_traits<T>::type_hash);
    EXPECT_EQ(schema.types[0].definition, agnocast::message_traits<T>::definition);
  });
}

TEST_F(StandardService, AddTwoIntsIsWhatRos2Sends) {
  example_interfaces::srv::AddTwoInts::Request request;
  request.a = 2;
  request.b = -3;
  const std::vector<std::uint8_t> expected_request{
      0,    1,    0,    0,                             // encapsulation: CDR little-endian
      2,    0,    0,    0,    0,    0,    0,    0,     // a
      0xFD, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,  // b
  };
  EXPECT_EQ(agnocast::cdr::serialize(request), expected_request);
  example_interfaces::srv::AddTwoInts::Response response;
  response.sum = -1;
  const std::vector<std::uint8_t> expected_response{0,    1,    0,    0,    0xFF, 0xFF,
                                                    0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  EXPECT_EQ(agnocast::cdr::serialize(response), expected_response);
}

TEST_F(StandardService, StdSrvsAreWhatRos2Sends) {
  // Empty parts: ROS 2's one placeholder byte.
  const std::vector<std::uint8_t> empty{0, 1, 0, 0, 0};
  EXPECT_EQ(agnocast::cdr::serialize(std_srvs::srv::Empty::Request{}), empty);
  EXPECT_EQ(agnocast::cdr::serialize(std_srvs::srv::Empty::Response{}), empty);
  EXPECT_EQ(agnocast::cdr::serialize(std_srvs::srv::Trigger::Request{}), empty);

  std_srvs::srv::SetBool::Request enable;
  enable.data = true;
  EXPECT_EQ(agnocast::cdr::serialize(enable), (std::vector<std::uint8_t>{0, 1, 0, 0, 1}));

  // bool, padding to 4, then the string's length (with its NUL), bytes and NUL.
  std_srvs::srv::SetBool::Response answer;
  answer.success = true;
  answer.message = "ok";
  const std::vector<std::uint8_t> expected{0, 1, 0, 0, 1, 0, 0, 0, 3, 0, 0, 0, 'o', 'k', 0};
  EXPECT_EQ(agnocast::cdr::serialize(answer), expected);
  std_srvs::srv::Trigger::Response triggered;
  triggered.success = true;
  triggered.message = "ok";
  EXPECT_EQ(agnocast::cdr::serialize(triggered), expected);

  std_srvs::srv::SetBool::Response read_back;
  agnocast::cdr::deserialize(expected, read_back);
  EXPECT_TRUE(read_back.success);
  EXPECT_EQ(read_back.message, "ok");
}

}  // namespace
