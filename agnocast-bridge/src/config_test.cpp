#include "config.hpp"

#include <gtest/gtest.h>

#include <string>

#include "agnocast/limits.hpp"

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

TEST(Config, MissingFileIsAConfigError) {
  EXPECT_THROW(load_config("/nonexistent/bridge.json"), ConfigError);
}

}  // namespace
}  // namespace agnocast_bridge
