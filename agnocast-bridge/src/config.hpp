// The bridge's configuration, read from JSON:
//   {"domain_id": 0,
//    "topics": [{"name": "/points", "type": "sensor_msgs/msg/PointCloud2",
//                "direction": "to_dds",
//                "qos": {"depth": 10, "reliable": true, "transient_local": false}}]}
// "qos" and each of its keys are optional (defaults below, those of ROS 2).
// Unknown keys are errors: a typo must not silently change behaviour.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace agnocast_bridge {

inline constexpr std::string_view default_config_path = "/etc/agnocast/bridge.json";

enum class Direction { to_dds, from_dds };

std::string_view direction_name(Direction direction);

struct TopicQos {
  std::size_t depth = 10;
  bool reliable = true;
  bool transient_local = false;
};

struct TopicConfig {
  std::string name;  // agnocast topic, "/points"
  std::string type;  // "sensor_msgs/msg/PointCloud2"
  Direction direction = Direction::to_dds;
  TopicQos qos;
};

struct Config {
  std::uint32_t domain_id = 0;
  std::vector<TopicConfig> topics;
};

// A configuration that cannot be used; key() is where, e.g. "topics[1].qos.depth".
class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string key, const std::string& problem)
      : std::runtime_error(key.empty() ? problem : key + ": " + problem), key_(std::move(key)) {}
  const std::string& key() const { return key_; }

 private:
  std::string key_;
};

// Throws ConfigError.
Config parse_config(std::string_view json_text);
Config load_config(const std::string& path);

}  // namespace agnocast_bridge
