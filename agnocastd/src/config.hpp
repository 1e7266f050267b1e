// agnocastd's configuration: a JSON file where every key is optional, read
// strictly (an unknown key or a wrong type is an error naming the key).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "agnocast/access_policy.hpp"

namespace agnocastd {

inline constexpr std::string_view default_config_path = "/etc/agnocast/agnocastd.json";

struct Config {
  // Load the module when it is not loaded (--no-load clears it).
  bool load_module = true;
  // insmod this file; without it, modprobe agnocast.
  std::optional<std::string> module_path;
  // Module parameters, already rendered as "name=value".
  std::map<std::string, std::string> module_parameters;
  // Unload on stop, if this instance loaded the module and nothing uses it.
  bool unload_on_exit = false;
  // Written to /proc/sys/fs/mqueue/<name> when set.
  struct Mqueue {
    std::optional<long> msg_max;
    std::optional<long> queues_max;
    std::optional<long> msgsize_max;

    bool operator==(const Mqueue&) const = default;
  } mqueue;
  // Applied to /dev/agnocast when set.
  struct Device {
    std::optional<std::string> group;
    std::optional<mode_t> mode;

    bool operator==(const Device&) const = default;
  } device;
  std::chrono::milliseconds sweep_interval{std::chrono::seconds(5)};
  // How long to wait for /dev/agnocast after loading the module.
  std::chrono::milliseconds device_timeout{std::chrono::seconds(5)};
  std::string log_level = "info";
  // The topic access policy loaded into the kernel; nullopt: none (anyone
  // with access to the device may publish and subscribe).
  std::optional<agnocast::AccessPolicy> access;

  bool operator==(const Config&) const = default;
};

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses a configuration document over the defaults; throws ConfigError.
Config parse_config(std::string_view json_text);
// Reads the file at path; a missing file yields the defaults only when
// missing_is_default (the default path), else it is an error.
Config load_config(const std::string& path, bool missing_is_default);

// True for the names spdlog knows: trace debug info warn error critical off.
bool is_log_level(std::string_view level);

}  // namespace agnocastd
