#include "config.hpp"

#include <array>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <variant>
#include <vector>

#include "access_principal.hpp"
#include "agnocast/limits.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/service_access.hpp"

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
  // Unsigned first: 2^64-1 (a ulong parameter) is not the long long -1.
  if (value.is_number_unsigned()) return std::to_string(value.get<std::uint64_t>());
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

// A rule as written: on topics (publish, subscribe) or on services (serve, call).
agnocast::WrittenAccessRule access_rule(const json& value, std::string_view key) {
  // "services" makes a services rule; a key of the other kind is named as such.
  const bool on_services = value.is_object() && value.contains("services");
  const Handler other_kind = [on_services](const json&, std::string_view k) {
    fail(k, on_services ? "a services rule has \"serve\" and \"call\"; \"topics\", \"publish\" "
                          "and \"subscribe\" belong to a topics rule"
                        : "a topics rule has \"publish\" and \"subscribe\"; \"serve\" and "
                          "\"call\" belong to a services rule");
  };
  if (value.is_object() && !on_services && !value.contains("topics")) {
    fail(key,
         "a rule needs \"topics\", the topic pattern it covers, or \"services\", the service "
         "pattern it covers");
  }
  if (on_services) {
    agnocast::ServiceAccessRule rule;
    read_object(value, key,
                {
                    {"services",
                     [&](const json& v, auto k) {
                       rule.services = text(v, k);
                       try {
                         agnocast::parse_service_pattern(rule.services);
                       } catch (const std::invalid_argument& error) {
                         fail(k, error.what());
                       }
                     }},
                    {"serve", [&](const json& v, auto k) { rule.serve = access_principals(v, k); }},
                    {"call", [&](const json& v, auto k) { rule.call = access_principals(v, k); }},
                    {"topics", other_kind},
                    {"publish", other_kind},
                    {"subscribe", other_kind},
                });
    return rule;
  }
  agnocast::AccessRule rule;
  read_object(
      value, key,
      {
          {"topics",
           [&](const json& v, auto k) {
             rule.topics = text(v, k);
             bool reserved = false;
             try {
               reserved =
                   agnocast::is_service_topic(agnocast::parse_topic_pattern(rule.topics).prefix);
             } catch (const std::invalid_argument& error) {
               fail(k, error.what());
             }
             if (reserved) {
               fail(k, "topics under " + std::string(agnocast::service_request_prefix) + " and " +
                           std::string(agnocast::service_reply_prefix) +
                           " carry services: write a services rule, e.g. {\"services\": "
                           "\"/arm/*\", \"serve\": [..], \"call\": [..]}");
             }
           }},
          {"publish", [&](const json& v, auto k) { rule.publish = access_principals(v, k); }},
          {"subscribe", [&](const json& v, auto k) { rule.subscribe = access_principals(v, k); }},
          {"serve", other_kind},
          {"call", other_kind},
      });
  return rule;
}

// How a rule is named in errors: access.rules[0] (topics "/**").
std::string rule_name(std::string_view key, const agnocast::WrittenAccessRule& rule) {
  if (const auto* topics = std::get_if<agnocast::AccessRule>(&rule)) {
    return std::string(key) + " (topics \"" + topics->topics + "\")";
  }
  return std::string(key) + " (services \"" + std::get<agnocast::ServiceAccessRule>(rule).services +
         "\")";
}

// The kernel takes the first rule that matches, so a services rule whose
// topics an earlier rule all matches (a topic rule "/**" above it) would
// silently never apply: refused, naming the rule that takes its place.
void check_reachable(const std::vector<agnocast::AccessRule>& earlier,
                     const std::vector<std::string>& earlier_names,
                     const agnocast::AccessRule& carrier, std::string_view key) {
  const agnocast::TopicPattern pattern = agnocast::parse_topic_pattern(carrier.topics);
  for (std::size_t i = 0; i < earlier.size(); ++i) {
    if (agnocast::covers(agnocast::parse_topic_pattern(earlier[i].topics), pattern)) {
      fail(key, "this services rule never applies: " + earlier_names[i] +
                    " comes first and matches every topic its services use (" + carrier.topics +
                    "); the first matching rule decides, so put this rule before it");
    }
  }
}

agnocast::AccessPolicy access_policy(const json& value, std::string_view key) {
  agnocast::AccessPolicy policy;
  // The config rule each kernel rule comes from, for errors.
  std::vector<std::string> rule_names;
  const auto add_rules = [&](const json& rules, std::string_view rules_key) {
    if (!rules.is_array()) fail(rules_key, "expected an array of rules, got " + type_of(rules));
    for (std::size_t i = 0; i < rules.size(); ++i) {
      const std::string rule_key = element_key(rules_key, i);
      const agnocast::WrittenAccessRule rule = access_rule(rules[i], rule_key);
      const std::string name = rule_name(rule_key, rule);
      if (const auto* topics = std::get_if<agnocast::AccessRule>(&rule)) {
        policy.rules.push_back(*topics);
        rule_names.push_back(name);
        continue;
      }
      // A services rule is two topic rules, in its place.
      for (const agnocast::AccessRule& carrier :
           agnocast::topic_rules_of(std::get<agnocast::ServiceAccessRule>(rule))) {
        check_reachable(policy.rules, rule_names, carrier, rule_key);
        policy.rules.push_back(carrier);
        rule_names.push_back(name);
      }
    }
  };
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
                  {"rules", add_rules},
              });
  // What the kernel takes, checked here so that --check-config says it.
  std::size_t principals = 0;
  for (const agnocast::AccessRule& rule : policy.rules) {
    principals += rule.publish.value_or(std::vector<agnocast::AccessPrincipal>{}).size() +
                  rule.subscribe.value_or(std::vector<agnocast::AccessPrincipal>{}).size();
  }
  if (policy.rules.size() > agnocast::access_policy_rules_max) {
    fail(std::string(key) + ".rules",
         "the rules make " + std::to_string(policy.rules.size()) +
             " rules in the kernel (a services rule makes two): at most " +
             std::to_string(agnocast::access_policy_rules_max));
  }
  if (principals > agnocast::access_policy_principals_max) {
    fail(std::string(key) + ".rules",
         "the rules name " + std::to_string(principals) +
             " users and groups in all (a services rule names its own twice): at most " +
             std::to_string(agnocast::access_policy_principals_max));
  }
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
  } catch (const json::exception& error) {  // a parse_error, or out_of_range for 1e400
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
