#include "config.hpp"

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "access_principal.hpp"

namespace agnocastd {
namespace {

using nlohmann::json;

[[noreturn]] void fail(std::string_view key, std::string_view problem) {
  throw ConfigError("config key '" + std::string(key) + "': " + std::string(problem));
}

std::string type_of(const json& value) { return value.type_name(); }

long positive_integer(const json& value, std::string_view key) {
  if (!value.is_number_integer()) fail(key, "expected a positive integer, got " + type_of(value));
  const auto number = value.get<long long>();
  if (number <= 0 || number > 1'000'000'000) fail(key, "must be between 1 and 1000000000");
  return static_cast<long>(number);
}

std::string text(const json& value, std::string_view key) {
  if (!value.is_string()) fail(key, "expected a string, got " + type_of(value));
  return value.get<std::string>();
}

bool boolean(const json& value, std::string_view key) {
  if (!value.is_boolean()) fail(key, "expected true or false, got " + type_of(value));
  return value.get<bool>();
}

std::chrono::milliseconds seconds(const json& value, std::string_view key) {
  if (!value.is_number()) fail(key, "expected a number of seconds, got " + type_of(value));
  const double number = value.get<double>();
  if (!(number >= 0.1 && number <= 86400)) fail(key, "must be between 0.1 and 86400 seconds");
  return std::chrono::milliseconds(static_cast<long>(number * 1000));
}

// "0660" -> 0660; permission bits only.
mode_t octal_mode(const json& value, std::string_view key) {
  const std::string digits = text(value, key);
  if (digits.empty() || digits.size() > 4 || digits.find_first_not_of("01234567") != digits.npos) {
    fail(key, "expected an octal mode such as \"0660\", got \"" + digits + "\"");
  }
  return static_cast<mode_t>(std::stoul(digits, nullptr, 8)) & 0777;
}

std::string parameter_value(const json& value, std::string_view key) {
  if (value.is_boolean()) return value.get<bool>() ? "1" : "0";
  if (value.is_number_integer()) return std::to_string(value.get<long long>());
  if (value.is_string()) {
    const auto string = value.get<std::string>();
    if (string.empty() || string.find_first_of(" \t\n\"") != string.npos) {
      fail(key, "must be non-empty without spaces or quotes");
    }
    return string;
  }
  fail(key, "expected an integer, a boolean or a string, got " + type_of(value));
}

using Handler = std::function<void(const json&, std::string_view key)>;

// Applies handlers[name] to every member of object; any other member is an error.
void read_object(const json& object, std::string_view where,
                 const std::map<std::string, Handler, std::less<>>& handlers) {
  if (!object.is_object()) fail(where.empty() ? "(top level)" : where, "expected an object");
  for (const auto& [name, value] : object.items()) {
    const std::string key = where.empty() ? name : std::string(where) + "." + name;
    const auto handler = handlers.find(name);
    if (handler == handlers.end()) fail(key, "unknown key");
    handler->second(value, key);
  }
}

std::string element_key(std::string_view key, std::size_t index) {
  return std::string(key) + "[" + std::to_string(index) + "]";
}

std::vector<agnocast::AccessPrincipal> access_principals(const json& value, std::string_view key) {
  if (!value.is_array()) {
    fail(key, "expected an array of \"user:NAME\", \"group:NAME\" or \"*\", got " + type_of(value));
  }
  std::vector<agnocast::AccessPrincipal> principals;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string element = element_key(key, i);
    try {
      principals.push_back(parse_access_principal(text(value[i], element)));
    } catch (const std::invalid_argument& error) {
      fail(element, error.what());
    }
  }
  return principals;
}

agnocast::AccessRule access_rule(const json& value, std::string_view key) {
  agnocast::AccessRule rule;
  bool has_topics = false;
  read_object(
      value, key,
      {
          {"topics",
           [&](const json& v, auto k) {
             rule.topics = text(v, k);
             try {
               agnocast::parse_topic_pattern(rule.topics);
             } catch (const std::invalid_argument& error) {
               fail(k, error.what());
             }
             has_topics = true;
           }},
          {"publish", [&](const json& v, auto k) { rule.publish = access_principals(v, k); }},
          {"subscribe", [&](const json& v, auto k) { rule.subscribe = access_principals(v, k); }},
      });
  if (!has_topics) fail(key, "a rule needs \"topics\", the topic pattern it covers");
  return rule;
}

agnocast::AccessPolicy access_policy(const json& value, std::string_view key) {
  agnocast::AccessPolicy policy;
  read_object(value, key,
              {
                  {"default",
                   [&](const json& v, auto k) {
                     const std::string decision = text(v, k);
                     if (decision != "allow" && decision != "deny") {
                       fail(k, "expected \"allow\" or \"deny\", got \"" + decision + "\"");
                     }
                     policy.default_allow = decision == "allow";
                   }},
                  {"rules",
                   [&](const json& v, auto k) {
                     if (!v.is_array()) fail(k, "expected an array of rules, got " + type_of(v));
                     for (std::size_t i = 0; i < v.size(); ++i) {
                       policy.rules.push_back(access_rule(v[i], element_key(k, i)));
                     }
                   }},
              });
  return policy;
}

}  // namespace

bool is_log_level(std::string_view level) {
  static constexpr std::array names{"trace", "debug", "info", "warn", "error", "critical", "off"};
  for (const auto* name : names) {
    if (level == name) return true;
  }
  return false;
}

Config parse_config(std::string_view json_text) {
  json document;
  try {
    document = json::parse(json_text, nullptr, true, /*ignore_comments=*/true);
  } catch (const json::parse_error& error) {
    throw ConfigError(std::string("not valid JSON: ") + error.what());
  }
  Config config;
  read_object(
      document, "",
      {
          {"module_path",
           [&](const json& v, auto key) {
             config.module_path = text(v, key);
             if (config.module_path->empty()) fail(key, "must not be empty");
           }},
          {"module_parameters",
           [&](const json& v, auto key) {
             if (!v.is_object()) fail(key, "expected an object of name: value");
             for (const auto& [name, value] : v.items()) {
               const std::string member = std::string(key) + "." + name;
               if (name.empty() ||
                   name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != name.npos) {
                 fail(member, "a parameter name uses only a-z, 0-9 and _");
               }
               config.module_parameters[name] = parameter_value(value, member);
             }
           }},
          {"unload_on_exit",
           [&](const json& v, auto key) { config.unload_on_exit = boolean(v, key); }},
          {"mqueue",
           [&](const json& v, auto key) {
             read_object(
                 v, key,
                 {
                     {"msg_max", [&](const json& w,
                                     auto k) { config.mqueue.msg_max = positive_integer(w, k); }},
                     {"queues_max",
                      [&](const json& w, auto k) {
                        config.mqueue.queues_max = positive_integer(w, k);
                      }},
                     {"msgsize_max",
                      [&](const json& w, auto k) {
                        config.mqueue.msgsize_max = positive_integer(w, k);
                      }},
                 });
           }},
          {"device",
           [&](const json& v, auto key) {
             read_object(v, key,
                         {
                             {"group",
                              [&](const json& w, auto k) {
                                config.device.group = text(w, k);
                                if (config.device.group->empty()) fail(k, "must not be empty");
                              }},
                             {"mode", [&](const json& w,
                                          auto k) { config.device.mode = octal_mode(w, k); }},
                         });
           }},
          {"sweep_interval_s",
           [&](const json& v, auto key) { config.sweep_interval = seconds(v, key); }},
          {"device_timeout_s",
           [&](const json& v, auto key) { config.device_timeout = seconds(v, key); }},
          {"log_level",
           [&](const json& v, auto key) {
             config.log_level = text(v, key);
             if (!is_log_level(config.log_level)) {
               fail(key, "expected one of trace, debug, info, warn, error, critical, off");
             }
           }},
          {"access", [&](const json& v, auto key) { config.access = access_policy(v, key); }},
      });
  return config;
}

Config load_config(const std::string& path, bool missing_is_default) {
  std::ifstream file(path);
  if (!file) {
    if (errno == ENOENT && missing_is_default) return Config{};
    throw ConfigError("cannot read config file " + path + ": " + std::strerror(errno));
  }
  std::ostringstream contents;
  contents << file.rdbuf();
  try {
    return parse_config(contents.str());
  } catch (const ConfigError& error) {
    throw ConfigError(path + ": " + error.what());
  }
}

}  // namespace agnocastd
