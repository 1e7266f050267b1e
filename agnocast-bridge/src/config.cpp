#include "config.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <utility>

#include "agnocast/limits.hpp"
#include "agnocast/naming.hpp"
#include "dds_names.hpp"

namespace agnocast_bridge {
namespace {

using nlohmann::json;

// DDS maps domain ids to UDP ports; 232 is the largest the default mapping allows.
constexpr std::uint32_t max_domain_id = 232;
// A bridged DDS call may take at most this long (ten minutes): an agnocast
// request pending longer is a hung request, not a slow one.
constexpr std::uint64_t max_service_timeout_ms = 600'000;
// Every other bound is the library's (<agnocast/limits.hpp>): what the
// configuration check accepts, the library accepts when the bridge starts.

void refuse_unknown_keys(const json& object, const std::string& where,
                         std::initializer_list<std::string_view> known) {
  for (const auto& [key, value] : object.items()) {
    bool is_known = false;
    for (const auto name : known) is_known = is_known || key == name;
    if (!is_known) {
      throw ConfigError(where.empty() ? key : where + "." + key, "unknown key");
    }
  }
}

const json& require(const json& object, const std::string& where, const char* key) {
  const auto found = object.find(key);
  if (found == object.end()) throw ConfigError(where + "." + key, "missing");
  return *found;
}

std::string require_string(const json& object, const std::string& where, const char* key) {
  const json& value = require(object, where, key);
  if (!value.is_string()) throw ConfigError(where + "." + key, "must be a string");
  return value.get<std::string>();
}

bool optional_bool(const json& object, const std::string& where, const char* key, bool fallback) {
  const auto found = object.find(key);
  if (found == object.end()) return fallback;
  if (!found->is_boolean()) throw ConfigError(where + "." + key, "must be true or false");
  return found->get<bool>();
}

TopicQos parse_qos(const json& object, const std::string& where) {
  if (!object.is_object()) throw ConfigError(where, "must be an object");
  refuse_unknown_keys(object, where, {"depth", "reliable", "transient_local"});
  TopicQos qos;
  if (const auto depth = object.find("depth"); depth != object.end()) {
    // The agnocast depth, and the DDS history depth, which is no longer.
    if (!depth->is_number_unsigned() || depth->get<std::uint64_t>() < agnocast::qos_depth_min ||
        depth->get<std::uint64_t>() > agnocast::qos_depth_max) {
      throw ConfigError(where + ".depth", "must be an integer from " +
                                              std::to_string(agnocast::qos_depth_min) + " to " +
                                              std::to_string(agnocast::qos_depth_max));
    }
    qos.depth = depth->get<std::size_t>();
  }
  qos.reliable = optional_bool(object, where, "reliable", qos.reliable);
  qos.transient_local = optional_bool(object, where, "transient_local", qos.transient_local);
  return qos;
}

Direction parse_direction(const json& object, const std::string& where) {
  const std::string direction = require_string(object, where, "direction");
  if (direction == "to_dds") return Direction::to_dds;
  if (direction == "from_dds") return Direction::from_dds;
  throw ConfigError(where + ".direction",
                    "must be \"to_dds\" or \"from_dds\", not \"" + direction + "\"");
}

TopicConfig parse_topic(const json& object, const std::string& where) {
  if (!object.is_object()) throw ConfigError(where, "must be an object");
  refuse_unknown_keys(object, where, {"name", "type", "direction", "qos"});
  TopicConfig topic;
  topic.name = require_string(object, where, "name");
  if (const std::string problem = agnocast::topic_name_problem(topic.name); !problem.empty()) {
    throw ConfigError(where + ".name", problem);
  }
  topic.type = require_string(object, where, "type");
  if (topic.type.size() > agnocast::type_name_max) {
    throw ConfigError(where + ".type", "message type name '" + topic.type +
                                           "' is too long: at most " +
                                           std::to_string(agnocast::type_name_max) + " characters");
  }
  try {
    dds_type_name(topic.type);
  } catch (const std::invalid_argument& error) {
    throw ConfigError(where + ".type", error.what());
  }
  topic.direction = parse_direction(object, where);
  if (const auto qos = object.find("qos"); qos != object.end()) {
    topic.qos = parse_qos(*qos, where + ".qos");
  }
  return topic;
}

ServiceConfig parse_service(const json& object, const std::string& where) {
  if (!object.is_object()) throw ConfigError(where, "must be an object");
  refuse_unknown_keys(object, where, {"name", "type", "direction", "timeout_ms"});
  ServiceConfig service;
  service.name = require_string(object, where, "name");
  if (const std::string problem = agnocast::service_name_problem(service.name); !problem.empty()) {
    throw ConfigError(where + ".name", problem);
  }
  service.type = require_string(object, where, "type");
  // The request and response types are named after the service type, and
  // the longer one must fit the library's bound.
  constexpr std::string_view longer_part = "_Response";
  if (service.type.size() + longer_part.size() > agnocast::type_name_max) {
    throw ConfigError(where + ".type",
                      "service type name '" + service.type + "' is too long: at most " +
                          std::to_string(agnocast::type_name_max - longer_part.size()) +
                          " characters");
  }
  try {
    dds_service_type_names(service.type);
  } catch (const std::invalid_argument& error) {
    throw ConfigError(where + ".type", error.what());
  }
  service.direction = parse_direction(object, where);
  if (const auto timeout = object.find("timeout_ms"); timeout != object.end()) {
    if (service.direction != Direction::from_dds) {
      throw ConfigError(where + ".timeout_ms",
                        "only a from_dds service waits for DDS: to_dds waits for agnocast");
    }
    if (!timeout->is_number_unsigned() || timeout->get<std::uint64_t>() < 1 ||
        timeout->get<std::uint64_t>() > max_service_timeout_ms) {
      throw ConfigError(where + ".timeout_ms",
                        "must be an integer from 1 to " + std::to_string(max_service_timeout_ms));
    }
    service.timeout = std::chrono::milliseconds(timeout->get<std::uint64_t>());
  }
  return service;
}

std::vector<ServiceConfig> parse_services(const json& document) {
  std::vector<ServiceConfig> services;
  const auto list = document.find("services");
  if (list == document.end()) return services;
  if (!list->is_array()) throw ConfigError("services", "must be an array");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string where = "services[" + std::to_string(i) + "]";
    ServiceConfig service = parse_service((*list)[i], where);
    // Both ways would make the bridge the agnocast server of the name and its own client.
    if (!seen.insert(service.name).second) {
      throw ConfigError(where + ".name", "service " + service.name +
                                             " is already bridged; a service is bridged "
                                             "one way, where its server is");
    }
    services.push_back(std::move(service));
  }
  return services;
}

}  // namespace

std::string_view direction_name(Direction direction) {
  return direction == Direction::to_dds ? "to_dds" : "from_dds";
}

Config parse_config(std::string_view json_text) {
  json document;
  try {
    document = json::parse(json_text);
  } catch (const json::exception& error) {  // a parse_error, or out_of_range for 1e400
    throw ConfigError("", std::string("not valid JSON: ") + error.what());
  }
  if (!document.is_object()) throw ConfigError("", "the configuration must be a JSON object");
  refuse_unknown_keys(document, "", {"domain_id", "topics", "services"});

  Config config;
  if (const auto domain = document.find("domain_id"); domain != document.end()) {
    if (!domain->is_number_unsigned() || domain->get<std::uint64_t>() > max_domain_id) {
      throw ConfigError("domain_id",
                        "must be an integer from 0 to " + std::to_string(max_domain_id));
    }
    config.domain_id = domain->get<std::uint32_t>();
  }
  // Topics, services or both; without either a bridge has nothing to do.
  const json no_topics = json::array();
  auto found = document.find("topics");
  if (found == document.end() && !document.contains("services")) {
    throw ConfigError("topics", "missing");
  }
  const json* topics = found != document.end() ? &*found : &no_topics;
  if (!topics->is_array()) throw ConfigError("topics", "must be an array");
  std::set<std::pair<std::string, Direction>> seen;
  for (std::size_t i = 0; i < topics->size(); ++i) {
    const std::string where = "topics[" + std::to_string(i) + "]";
    TopicConfig topic = parse_topic((*topics)[i], where);
    if (!seen.emplace(topic.name, topic.direction).second) {
      throw ConfigError(where + ".name", "topic " + topic.name + " is already bridged " +
                                             std::string(direction_name(topic.direction)));
    }
    config.topics.push_back(std::move(topic));
  }
  // A topic bridged both ways must have one type, as the topic itself has.
  for (const auto& a : config.topics) {
    for (std::size_t i = 0; i < config.topics.size(); ++i) {
      const auto& b = config.topics[i];
      if (a.name == b.name && a.type != b.type) {
        throw ConfigError(
            "topics[" + std::to_string(i) + "].type",
            "topic " + b.name + " is bridged with two types, " + a.type + " and " + b.type);
      }
    }
  }
  config.services = parse_services(document);
  return config;
}

Config load_config(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw ConfigError("", "cannot read " + path);
  std::ostringstream text;
  text << file.rdbuf();
  return parse_config(text.str());
}

}  // namespace agnocast_bridge
