// agnocast-bridge's configuration over any text: a Config or a ConfigError
// naming the key, and what it accepts the library and DDS take as it is:
// topic and type names valid, depths within <agnocast/limits.hpp>, no topic
// bridged twice one way nor with two types.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "agnocast/limits.hpp"
#include "agnocast/naming.hpp"
#include "config.hpp"
#include "dds_names.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  agnocast_bridge::Config config;
  try {
    config = agnocast_bridge::parse_config(text);
  } catch (const agnocast_bridge::ConfigError&) {
    return 0;
  }
  if (config.domain_id > 232) std::abort();
  std::set<std::pair<std::string, agnocast_bridge::Direction>> bridged;
  std::map<std::string, std::string> types;
  for (const agnocast_bridge::TopicConfig& topic : config.topics) {
    if (!agnocast::is_valid_topic_name(topic.name)) std::abort();
    if (topic.type.size() > agnocast::type_name_max) std::abort();
    if (topic.qos.depth < agnocast::qos_depth_min || topic.qos.depth > agnocast::qos_depth_max) {
      std::abort();
    }
    try {
      agnocast_bridge::dds_type_name(topic.type);
    } catch (const std::invalid_argument&) {
      std::abort();
    }
    agnocast_bridge::dds_topic_name(topic.name);
    if (!bridged.emplace(topic.name, topic.direction).second) std::abort();
    const auto [known, first] = types.emplace(topic.name, topic.type);
    if (!first && known->second != topic.type) std::abort();
  }
  return 0;
}
