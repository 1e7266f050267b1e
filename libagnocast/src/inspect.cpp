#include "agnocast/inspect.hpp"

#include <unistd.h>

#include "agnocast/errors.hpp"
#include "device.hpp"

namespace agnocast {

bool module_loaded() { return ::access("/dev/agnocast", F_OK) == 0; }

std::optional<Version> module_version() {
  try {
    return detail::Device::open().get_version();
  } catch (const ModuleNotLoaded&) {
    return std::nullopt;
  }
}

std::vector<TopicSummary> list_topics() { return detail::Device::open().list_topics(); }

std::optional<TopicInfo> topic_info(const std::string& topic) {
  TopicInfo info;
  if (!detail::Device::open().topic_info(topic, info)) return std::nullopt;
  return info;
}

std::vector<ProcessInfo> list_processes() { return detail::Device::open().list_processes(); }

std::optional<std::vector<std::uint8_t>> topic_schema(const std::string& topic) {
  return detail::Device::open().topic_schema(topic);
}

}  // namespace agnocast
