// The bridge's configuration, read from JSON:
//   {"domain_id": 0,
//    "topics": [{"name": "/points", "type": "sensor_msgs/msg/PointCloud2",
//                "direction": "to_dds",
//                "qos": {"depth": 10, "reliable": true, "transient_local": false}}],
//    "services": [{"name": "/add_two_ints", "type": "example_interfaces/srv/AddTwoInts",
//                  "direction": "from_dds", "timeout_ms": 5000}]}
// "qos" and each of its keys are optional (defaults below, those of ROS 2);
// so are "services" and a service's "timeout_ms".
// Unknown keys are errors: a typo must not silently change behaviour.
#pragma once

#include <chrono>
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

// A service bridged as rmw_cyclonedds_cpp serves services. to_dds: an agnocast
// server is called from DDS (the bridge replies on DDS as its client);
// from_dds: a DDS server is called from agnocast (the bridge serves the name
// in agnocast and asks on DDS).
struct ServiceConfig {
  std::string name;  // agnocast service, "/add_two_ints"
  std::string type;  // "example_interfaces/srv/AddTwoInts"
  Direction direction = Direction::to_dds;
  // from_dds: how long a request may wait for the DDS server's reply before
  // the agnocast client's request fails (ServiceUnavailable).
  std::chrono::milliseconds timeout{5000};
};

struct Config {
  std::uint32_t domain_id = 0;
  std::vector<TopicConfig> topics;
  std::vector<ServiceConfig> services;
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
