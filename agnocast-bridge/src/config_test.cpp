#include "config.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "agnocast/limits.hpp"
#include "agnocast/naming.hpp"

namespace agnocast_bridge {
namespace {

std::string error_key(const std::string& json) {
  try {
    parse_config(json);
  } catch (const ConfigError& error) {
    return error.key();
  }
  return "(accepted)";
}

TEST(Config, SpecExampleParses) {
  const Config config = parse_config(R"({"domain_id": 3,
    "topics": [{"name": "/points", "type": "sensor_msgs/msg/PointCloud2", "direction": "to_dds"},
               {"name": "/cmd_vel", "type": "geometry_msgs/msg/Twist", "direction": "from_dds",
                "qos": {"depth": 5, "reliable": false, "transient_local": true}}]})");
  EXPECT_EQ(config.domain_id, 3u);
  ASSERT_EQ(config.topics.size(), 2u);
  EXPECT_EQ(config.topics[0].name, "/points");
  EXPECT_EQ(config.topics[0].direction, Direction::to_dds);
  EXPECT_EQ(config.topics[0].qos.depth, 10u);
  EXPECT_TRUE(config.topics[0].qos.reliable);
  EXPECT_FALSE(config.topics[0].qos.transient_local);
  EXPECT_EQ(config.topics[1].type, "geometry_msgs/msg/Twist");
  EXPECT_EQ(config.topics[1].direction, Direction::from_dds);
  EXPECT_EQ(config.topics[1].qos.depth, 5u);
  EXPECT_FALSE(config.topics[1].qos.reliable);
  EXPECT_TRUE(config.topics[1].qos.transient_local);
}

TEST(Config, OneTopicMayBeBridgedBothWays) {
  const Config config = parse_config(R"({"topics": [
    {"name": "/t", "type": "std_msgs/msg/Header", "direction": "to_dds"},
    {"name": "/t", "type": "std_msgs/msg/Header", "direction": "from_dds"}]})");
  EXPECT_EQ(config.domain_id, 0u);
  EXPECT_EQ(config.topics.size(), 2u);
}

TEST(Config, ErrorsNameTheKey) {
  const std::string topic = R"("name": "/t", "type": "std_msgs/msg/Header", "direction": "to_dds")";
  EXPECT_EQ(error_key("{"), "");
  // A number no double holds: nlohmann throws out_of_range, not parse_error.
  EXPECT_EQ(error_key(R"({"domain_id": 8889888e44444444, "topics": []})"), "");
  EXPECT_EQ(error_key("[]"), "");
  EXPECT_EQ(error_key("{}"), "topics");
  EXPECT_EQ(error_key(R"({"topics": {}})"), "topics");
  EXPECT_EQ(error_key(R"({"topics": [], "domain": 1})"), "domain");
  EXPECT_EQ(error_key(R"({"topics": [], "domain_id": 233})"), "domain_id");
  EXPECT_EQ(error_key(R"({"topics": [], "domain_id": -1})"), "domain_id");
  EXPECT_EQ(error_key(R"({"topics": [{}]})"), "topics[0].name");
  EXPECT_EQ(
      error_key(R"({"topics": [{"name": "no-slash", "type": "a/msg/B", "direction": "to_dds"}]})"),
      "topics[0].name");
  EXPECT_EQ(error_key(R"({"topics": [{"name": "/t", "type": "Header", "direction": "to_dds"}]})"),
            "topics[0].type");
  EXPECT_EQ(error_key(R"({"topics": [{"name": "/t", "type": "a/msg/B", "direction": "up"}]})"),
            "topics[0].direction");
  EXPECT_EQ(error_key(R"({"topics": [{)" + topic + R"(, "qos": {"depth": 0}}]})"),
            "topics[0].qos.depth");
  EXPECT_EQ(error_key(R"({"topics": [{)" + topic + R"(, "qos": {"reliable": 1}}]})"),
            "topics[0].qos.reliable");
  EXPECT_EQ(error_key(R"({"topics": [{)" + topic + R"(, "qos": {"history": 1}}]})"),
            "topics[0].qos.history");
  EXPECT_EQ(error_key(R"({"topics": [{)" + topic + R"(}, {)" + topic + R"(}]})"), "topics[1].name");
  EXPECT_EQ(error_key(R"({"topics": [{)" + topic +
                      R"(}, {"name": "/t", "type": "a/msg/B", "direction": "from_dds"}]})"),
            "topics[1].type");
}

std::string with_depth(const std::string& depth) {
  return R"({"topics": [{"name": "/t", "type": "std_msgs/msg/Header", "direction": "to_dds"},
                        {"name": "/u", "type": "std_msgs/msg/Header", "direction": "from_dds",
                         "qos": {"depth": )" +
         depth + "}}]}";
}

// The bounds are the library's: a depth the check accepts is one the library
// accepts when the bridge creates its endpoints.
TEST(Config, DepthIsWithinTheLibrarysLimits) {
  EXPECT_EQ(agnocast::qos_depth_min, 1u);
  EXPECT_EQ(parse_config(with_depth("1")).topics[1].qos.depth, 1u);
  EXPECT_EQ(parse_config(with_depth(std::to_string(agnocast::qos_depth_max))).topics[1].qos.depth,
            agnocast::qos_depth_max);
  for (const std::string& depth :
       {std::string("0"), std::to_string(agnocast::qos_depth_max + 1), std::string("2000"),
        std::string("65536"), std::string("-1"), std::string("1.5"), std::string("\"10\"")}) {
    try {
      parse_config(with_depth(depth));
      ADD_FAILURE() << "depth " << depth << " accepted";
    } catch (const ConfigError& error) {
      EXPECT_EQ(error.key(), "topics[1].qos.depth") << depth;
      EXPECT_STREQ(error.what(), ("topics[1].qos.depth: must be an integer from 1 to " +
                                  std::to_string(agnocast::qos_depth_max))
                                     .c_str());
    }
  }
}

TEST(Config, TypeNameLengthIsTheLibrarys) {
  const auto config_with_type = [](const std::string& type) {
    return R"({"topics": [{"name": "/t", "direction": "to_dds", "type": ")" + type + R"("}]})";
  };
  // "p/msg/" and a type name making up the longest name the library takes.
  const std::string longest = "p/msg/" + std::string(agnocast::type_name_max - 6, 'T');
  EXPECT_EQ(parse_config(config_with_type(longest)).topics[0].type, longest);
  EXPECT_EQ(error_key(config_with_type(longest + "T")), "topics[0].type");
}

TEST(Config, ServicesParse) {
  const Config config = parse_config(R"({"services": [
    {"name": "/add_two_ints", "type": "example_interfaces/srv/AddTwoInts", "direction": "from_dds",
     "timeout_ms": 250},
    {"name": "/arm/enable", "type": "std_srvs/srv/SetBool", "direction": "to_dds"}]})");
  EXPECT_TRUE(config.topics.empty());
  ASSERT_EQ(config.services.size(), 2u);
  EXPECT_EQ(config.services[0].name, "/add_two_ints");
  EXPECT_EQ(config.services[0].type, "example_interfaces/srv/AddTwoInts");
  EXPECT_EQ(config.services[0].direction, Direction::from_dds);
  EXPECT_EQ(config.services[0].timeout, std::chrono::milliseconds(250));
  EXPECT_EQ(config.services[1].direction, Direction::to_dds);
  EXPECT_EQ(config.services[1].timeout, std::chrono::milliseconds(5000));
}

std::string with_service(const std::string& fields) {
  return R"({"topics": [], "services": [{"name": "/s", "type": "std_srvs/srv/Empty",
             "direction": "from_dds"}, {)" +
         fields + "}]}";
}

TEST(Config, ServiceErrorsNameTheKey) {
  const std::string service = R"("name": "/s2", "type": "std_srvs/srv/Trigger")";
  EXPECT_EQ(error_key(R"({"services": {}})"), "services");
  EXPECT_EQ(error_key(R"({"services": [1]})"), "services[0]");
  EXPECT_EQ(error_key(R"({"services": [null]})"), "services[0]");
  EXPECT_EQ(error_key(with_service("")), "services[1].name");
  EXPECT_EQ(error_key(with_service(service)), "services[1].direction");
  EXPECT_EQ(error_key(with_service(service + R"(, "direction": "both")")), "services[1].direction");
  EXPECT_EQ(error_key(with_service(service + R"(, "direction": 1)")), "services[1].direction");
  EXPECT_EQ(error_key(with_service(service + R"(, "direction": "to_dds", "qos": {})")),
            "services[1].qos");
  EXPECT_EQ(error_key(with_service(R"("name": 7, "type": "std_srvs/srv/Empty")")),
            "services[1].name");
  // The library's service name rules.
  for (const std::string& name :
       {std::string("s"), std::string("/a b"), std::string("/a//b"), std::string("/"),
        std::string("/_service_request/x"), std::string("/a/"),
        "/" + std::string(agnocast::service_name_max, 'n'), std::string("/\\u00e9"),
        std::string("/a\\u0000b")}) {
    EXPECT_EQ(error_key(with_service(R"("name": ")" + name +
                                     R"(", "type": "std_srvs/srv/Empty", "direction": "to_dds")")),
              "services[1].name")
        << name;
  }
  for (const std::string& type :
       {std::string("std_srvs/msg/Empty"), std::string("Empty"), std::string("std_srvs/srv/"),
        std::string("/srv/Empty"), std::string("a/srv/b/c"), std::string(""),
        "p/srv/" + std::string(agnocast::type_name_max, 'T')}) {
    EXPECT_EQ(error_key(with_service(R"("name": "/s2", "direction": "to_dds", "type": ")" + type +
                                     R"(")")),
              "services[1].type")
        << type;
  }
  // One way only: both would make the bridge the name's server and its own client.
  EXPECT_EQ(error_key(with_service(
                R"("name": "/s", "type": "std_srvs/srv/Empty", "direction": "to_dds")")),
            "services[1].name");
}

TEST(Config, ServiceTimeoutIsBounded) {
  const std::string service = R"("name": "/s2", "type": "std_srvs/srv/Trigger")";
  EXPECT_EQ(parse_config(with_service(service + R"(, "direction": "from_dds", "timeout_ms": 1)"))
                .services[1]
                .timeout,
            std::chrono::milliseconds(1));
  EXPECT_EQ(
      parse_config(with_service(service + R"(, "direction": "from_dds", "timeout_ms": 600000)"))
          .services[1]
          .timeout,
      std::chrono::minutes(10));
  for (const std::string& timeout :
       {std::string("0"), std::string("600001"), std::string("-5"), std::string("1.5"),
        std::string("\"100\""), std::string("null"), std::string("1e30"),
        std::string("18446744073709551615")}) {
    EXPECT_EQ(
        error_key(with_service(service + R"(, "direction": "from_dds", "timeout_ms": )" + timeout)),
        "services[1].timeout_ms")
        << timeout;
  }
  // A to_dds service waits for an agnocast server, which fails its own requests.
  EXPECT_EQ(error_key(with_service(service + R"(, "direction": "to_dds", "timeout_ms": 100)")),
            "services[1].timeout_ms");
}

TEST(Config, ServiceTypeNameLengthLeavesRoomForItsParts) {
  const auto config_with_type = [](const std::string& type) {
    return R"({"services": [{"name": "/s", "direction": "to_dds", "type": ")" + type + R"("}]})";
  };
  // "p/srv/", a name, and "_Response" make up the longest type the library takes.
  const std::string longest = "p/srv/" + std::string(agnocast::type_name_max - 6 - 9, 'T');
  EXPECT_EQ(parse_config(config_with_type(longest)).services[0].type, longest);
  EXPECT_EQ(error_key(config_with_type(longest + "T")), "services[0].type");
}

TEST(Config, MissingFileIsAConfigError) {
  EXPECT_THROW(load_config("/nonexistent/bridge.json"), ConfigError);
}

}  // namespace
}  // namespace agnocast_bridge
