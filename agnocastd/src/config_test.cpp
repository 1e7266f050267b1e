#include "config.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "agnocast/naming.hpp"

namespace agnocastd {
namespace {

std::string error_of(std::string_view json) {
  try {
    parse_config(json);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "";
}

TEST(Config, EmptyObjectGivesDefaults) {
  const Config config = parse_config("{}");
  EXPECT_TRUE(config.load_module);
  EXPECT_FALSE(config.module_path);
  EXPECT_TRUE(config.module_parameters.empty());
  EXPECT_FALSE(config.unload_on_exit);
  EXPECT_FALSE(config.mqueue.msg_max);
  EXPECT_FALSE(config.device.group);
  EXPECT_EQ(config.sweep_interval, std::chrono::seconds(5));
  EXPECT_EQ(config.log_level, "info");
}

TEST(Config, ReadsEveryKey) {
  const Config config = parse_config(R"({
    "module_path": "/lib/modules/x/agnocast.ko",
    "module_parameters": {"pool_size": 1048576, "pool_count": 8, "debug": true, "name": "x"},
    "unload_on_exit": true,
    "mqueue": {"msg_max": 64, "queues_max": 1024, "msgsize_max": 8192},
    "device": {"group": "agnocast", "mode": "0660"},
    "sweep_interval_s": 0.5,
    "device_timeout_s": 2,
    "log_level": "debug"
  })");
  EXPECT_EQ(config.module_path, "/lib/modules/x/agnocast.ko");
  EXPECT_EQ(config.module_parameters.at("pool_size"), "1048576");
  EXPECT_EQ(config.module_parameters.at("debug"), "1");
  EXPECT_EQ(config.module_parameters.at("name"), "x");
  EXPECT_EQ(parse_config(R"({"module_parameters": {"pool_base": 18446744073709551615}})")
                .module_parameters.at("pool_base"),
            "18446744073709551615");
  EXPECT_EQ(parse_config(R"({"module_parameters": {"offset": -4}})").module_parameters.at("offset"),
            "-4");
  EXPECT_TRUE(config.unload_on_exit);
  EXPECT_EQ(config.mqueue.msg_max, 64);
  EXPECT_EQ(config.mqueue.queues_max, 1024);
  EXPECT_EQ(config.mqueue.msgsize_max, 8192);
  EXPECT_EQ(config.device.group, "agnocast");
  EXPECT_EQ(config.device.mode, 0660u);
  EXPECT_EQ(config.sweep_interval, std::chrono::milliseconds(500));
  EXPECT_EQ(config.device_timeout, std::chrono::seconds(2));
  EXPECT_EQ(config.log_level, "debug");
}

TEST(Config, ErrorsNameTheKey) {
  EXPECT_EQ(error_of(R"({"colour": 1})"), "config key 'colour': unknown key");
  EXPECT_EQ(error_of(R"({"mqueue": {"msg_max": "10"}})"),
            "config key 'mqueue.msg_max': expected a positive integer, got string");
  EXPECT_EQ(error_of(R"({"mqueue": {"msg_max": 0}})"),
            "config key 'mqueue.msg_max': must be between 1 and 1000000000");
  EXPECT_EQ(error_of(R"({"mqueue": {"size": 1}})"), "config key 'mqueue.size': unknown key");
  EXPECT_EQ(error_of(R"({"mqueue": 3})"), "config key 'mqueue': expected an object");
  EXPECT_EQ(error_of(R"({"unload_on_exit": "yes"})"),
            "config key 'unload_on_exit': expected true or false, got string");
  EXPECT_EQ(error_of(R"({"device": {"mode": "0966"}})"),
            "config key 'device.mode': expected an octal mode such as \"0660\", got \"0966\"");
  EXPECT_EQ(error_of(R"({"module_parameters": {"pool size": 1}})"),
            "config key 'module_parameters.pool size': a parameter name uses only a-z, 0-9 and _");
  EXPECT_EQ(error_of(R"({"module_parameters": {"pool_size": 1.5}})"),
            "config key 'module_parameters.pool_size': expected an integer, a boolean or a "
            "string, got number");
  EXPECT_EQ(error_of(R"({"sweep_interval_s": 0})"),
            "config key 'sweep_interval_s': must be between 0.1 and 86400 seconds");
  EXPECT_EQ(error_of(R"({"log_level": "loud"})"),
            "config key 'log_level': expected one of trace, debug, info, warn, error, critical, "
            "off");
  EXPECT_EQ(error_of("[]"), "config key '(top level)': expected an object");
  EXPECT_EQ(error_of("{").rfind("not valid JSON: ", 0), 0u);
  // A number no double holds: nlohmann throws out_of_range, not parse_error.
  EXPECT_EQ(error_of(R"({"sweep_interval_s": 2684E35456})").rfind("not valid JSON: ", 0), 0u);
}

TEST(ConfigAccess, AbsentMeansNoPolicy) { EXPECT_FALSE(parse_config("{}").access); }

TEST(ConfigAccess, ReadsRulesWithNamesAndIdsResolved) {
  // root (uid 0, group 0) exists on every system the tests run on.
  const Config config = parse_config(R"({"access": {
    "default": "deny",
    "rules": [
      {"topics": "/safety/**", "publish": ["group:root", "user:1234"],
       "subscribe": ["user:root", "group:4321", "*"]},
      {"topics": "/public/*", "subscribe": []},
      {"topics": "/exact"}
    ]}})");
  using agnocast::AccessPrincipal;
  using Kind = AccessPrincipal::Kind;
  ASSERT_TRUE(config.access);
  EXPECT_FALSE(config.access->default_allow);
  ASSERT_EQ(config.access->rules.size(), 3u);
  const auto& safety = config.access->rules[0];
  EXPECT_EQ(safety.topics, "/safety/**");
  EXPECT_EQ(safety.publish, (std::vector<AccessPrincipal>{{Kind::group, 0}, {Kind::user, 1234}}));
  EXPECT_EQ(safety.subscribe, (std::vector<AccessPrincipal>{
                                  {Kind::user, 0}, {Kind::group, 4321}, {Kind::anyone, 0}}));
  EXPECT_FALSE(config.access->rules[1].publish);
  EXPECT_EQ(config.access->rules[1].subscribe, std::vector<AccessPrincipal>{});
  EXPECT_FALSE(config.access->rules[2].publish);
  EXPECT_FALSE(config.access->rules[2].subscribe);
  EXPECT_TRUE(parse_config(R"({"access": {}})").access->default_allow);
}

TEST(ConfigAccess, ErrorsNameTheKeyPath) {
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "publish": ["group:root",
                                               "group:no_such_group_x"]}]}})"),
            "config key 'access.rules[0].publish[1]': no group named 'no_such_group_x'");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a"},
                                              {"topics": "/b", "subscribe": ["user:no_such_user_x"]}]}})"),
            "config key 'access.rules[1].subscribe[0]': no user named 'no_such_user_x'");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "publish": ["root"]}]}})"),
            "config key 'access.rules[0].publish[0]': expected \"user:NAME\", \"group:NAME\" "
            "(or a numeric id) or \"*\", got \"root\"");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "publish": ["team:x"]}]}})"),
            "config key 'access.rules[0].publish[0]': expected \"user:NAME\", \"group:NAME\" "
            "(or a numeric id) or \"*\", got \"team:x\"");
  EXPECT_EQ(
      error_of(R"({"access": {"rules": [{"topics": "/a", "publish": ["user:root\u0000x"]}]}})"),
      "config key 'access.rules[0].publish[0]': a user name may not hold a NUL byte");
  EXPECT_EQ(
      error_of(R"({"access": {"rules": [{"topics": "/a", "publish": ["user:4294967295"]}]}})"),
      "config key 'access.rules[0].publish[0]': id 4294967295 is out of range");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "publish": "group:root"}]}})"),
            "config key 'access.rules[0].publish': expected an array of \"user:NAME\", "
            "\"group:NAME\" or \"*\", got string");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "publish": [0]}]}})"),
            "config key 'access.rules[0].publish[0]': expected a string, got number");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"publish": []}]}})"),
            "config key 'access.rules[0]': a rule needs \"topics\", the topic pattern it covers, "
            "or \"services\", the service pattern it covers");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "read": []}]}})"),
            "config key 'access.rules[0].read': unknown key");
  EXPECT_EQ(error_of(R"({"access": {"default": "maybe"}})"),
            "config key 'access.default': expected \"allow\" or \"deny\", got \"maybe\"");
  EXPECT_EQ(error_of(R"({"access": {"rules": {}}})"),
            "config key 'access.rules': expected an array of rules, got object");
  EXPECT_EQ(error_of(R"({"access": {"rule": []}})"), "config key 'access.rule': unknown key");
  EXPECT_EQ(error_of(R"({"access": []})"), "config key 'access': expected an object");
  const std::string bad_pattern = error_of(R"({"access": {"rules": [{"topics": "/a/**/b"}]}})");
  EXPECT_EQ(
      bad_pattern.rfind("config key 'access.rules[0].topics': access rule topics '/a/**/b'", 0), 0u)
      << bad_pattern;
  EXPECT_NE(error_of(R"({"access": {"rules": [{"topics": "safety/**"}]}})"), "");
}

TEST(ConfigAccess, ServicesRulesBecomeTwoTopicRulesInPlace) {
  using agnocast::AccessPrincipal;
  using agnocast::AccessRule;
  using Kind = AccessPrincipal::Kind;
  using Principals = std::vector<AccessPrincipal>;
  const Config config = parse_config(R"({"access": {"default": "deny", "rules": [
      {"topics": "/chatter", "publish": ["*"]},
      {"services": "/arm/*", "serve": ["user:10"], "call": ["group:20", "user:0"]},
      {"services": "/**", "call": []},
      {"topics": "/**", "subscribe": ["group:0"]}]}})");
  ASSERT_TRUE(config.access);
  const Principals anyone{{Kind::anyone, 0}};
  const Principals servers{{Kind::user, 10}};
  const Principals callers{{Kind::group, 20}, {Kind::user, 0}};
  EXPECT_EQ(config.access->rules, (std::vector<AccessRule>{
                                      {"/chatter", anyone, std::nullopt},
                                      {"/_service_request/arm/*", callers, servers},
                                      {"/_service_reply/arm/*", servers, callers},
                                      {"/_service_request/**", Principals{}, std::nullopt},
                                      {"/_service_reply/**", std::nullopt, Principals{}},
                                      {"/**", std::nullopt, Principals{{Kind::group, 0}}},
                                  }));
}

TEST(ConfigAccess, ServicesRuleErrorsNameTheKeyPath) {
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "services": "/a"}]}})"),
            "config key 'access.rules[0].topics': a services rule has \"serve\" and \"call\"; "
            "\"topics\", \"publish\" and \"subscribe\" belong to a topics rule");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"services": "/a", "publish": []}]}})"),
            "config key 'access.rules[0].publish': a services rule has \"serve\" and "
            "\"call\"; \"topics\", \"publish\" and \"subscribe\" belong to a topics rule");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "call": []}]}})"),
            "config key 'access.rules[0].call': a topics rule has \"publish\" and "
            "\"subscribe\"; \"serve\" and \"call\" belong to a services rule");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"serve": []}]}})"),
            "config key 'access.rules[0]': a rule needs \"topics\", the topic pattern it "
            "covers, or \"services\", the service pattern it covers");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"services": "/a", "serve": ["root"]}]}})"),
            "config key 'access.rules[0].serve[0]': expected \"user:NAME\", \"group:NAME\" "
            "(or a numeric id) or \"*\", got \"root\"");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"services": "/a", "call": "*"}]}})"),
            "config key 'access.rules[0].call': expected an array of \"user:NAME\", "
            "\"group:NAME\" or \"*\", got string");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"services": 7}]}})"),
            "config key 'access.rules[0].services': expected a string, got number");
  for (const char* pattern : {"arm/*", "/a/**/b", "/", "", "/a b", "/_service_request/x"}) {
    const std::string error =
        error_of(R"({"access": {"rules": [{"services": ")" + std::string(pattern) + R"("}]}})");
    EXPECT_EQ(error.rfind("config key 'access.rules[0].services': access rule services '" +
                              std::string(pattern) + "': ",
                          0),
              0u)
        << error;
  }
  const std::string too_long = "/" + std::string(agnocast::service_name_max, 'a');
  EXPECT_NE(
      error_of(R"({"access": {"rules": [{"services": ")" + too_long + R"("}]}})").find("too long"),
      std::string::npos);
}

TEST(ConfigAccess, TopicRulesMayNotNameTheTopicsThatCarryServices) {
  for (const char* pattern : {"/_service_request/**", "/_service_reply/arm/enable",
                              "/_service_request", "/_service_reply/*"}) {
    EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": ")" + std::string(pattern) +
                       R"(", "publish": []}]}})"),
              "config key 'access.rules[0].topics': topics under /_service_request and "
              "/_service_reply carry services: write a services rule, e.g. {\"services\": "
              "\"/arm/*\", \"serve\": [..], \"call\": [..]}")
        << pattern;
  }
  // Names that only look alike are ordinary topics.
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/_service_requests/**"}]}})"), "");
}

TEST(ConfigAccess, TheKernelsLimitsCountTheTopicRulesServicesRulesMake) {
  const auto rules = [](std::size_t topics, std::size_t services, const std::string& who) {
    std::string text = R"({"access": {"rules": [)";
    for (std::size_t i = 0; i < topics + services; ++i) {
      if (i > 0) text += ",";
      text += i < topics ? R"({"topics": "/t)" + std::to_string(i) + R"(", "publish": )" + who + "}"
                         : R"({"services": "/s)" + std::to_string(i) + R"(", "call": )" + who + "}";
    }
    return text + "]}}";
  };
  EXPECT_EQ(error_of(rules(254, 1, "[]")), "");
  EXPECT_EQ(error_of(rules(128, 65, "[]")),
            "config key 'access.rules': the rules make 258 rules in the kernel (a services rule "
            "makes two): at most 256");
  std::string many = "[";
  for (int i = 0; i < 32; ++i)
    many += std::string(i > 0 ? "," : "") + "\"user:" + std::to_string(i) + "\"";
  many += "]";
  EXPECT_EQ(error_of(rules(128, 0, many)), "");  // 4096 users and groups
  EXPECT_EQ(error_of(rules(127, 1, many)),
            "config key 'access.rules': the rules name 4128 users and groups in all (a services "
            "rule names its own twice): at most 4096");
}

TEST(ConfigAccess, AServicesRuleAnEarlierRuleHidesIsRefusedNamingThatRule) {
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/**", "publish": ["*"]},
                                                {"services": "/arm/*", "serve": []}]}})"),
            "config key 'access.rules[1]': this services rule never applies: access.rules[0] "
            "(topics \"/**\") comes first and matches every topic its services use "
            "(/_service_request/arm/*); the first matching rule decides, so put this rule "
            "before it");
  EXPECT_NE(error_of(R"({"access": {"rules": [{"services": "/arm/**"}, {"topics": "/a"},
                                                {"services": "/arm/enable"}]}})")
                .find("'access.rules[2]': this services rule never applies: access.rules[0] "
                      "(services \"/arm/**\")"),
            std::string::npos);
  // Narrower first, or the topic rule "/**" last: every rule can apply.
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"services": "/arm/enable"},
                                                {"services": "/arm/**"},
                                                {"topics": "/arm/**"},
                                                {"services": "/**"},
                                                {"topics": "/**"}]}})"),
            "");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/*"}, {"services": "/*"}]}})"), "");
}

TEST(Config, MissingFileIsDefaultOnlyForTheDefaultPath) {
  const std::string path = ::testing::TempDir() + "/agnocastd-missing.json";
  std::remove(path.c_str());
  EXPECT_EQ(load_config(path, /*missing_is_default=*/true).log_level, "info");
  EXPECT_THROW(load_config(path, /*missing_is_default=*/false), ConfigError);
}

TEST(Config, FileErrorsNameTheFile) {
  const std::string path = ::testing::TempDir() + "/agnocastd-bad.json";
  std::ofstream(path) << R"({"sweep_interval_s": "often"})";
  try {
    load_config(path, false);
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()),
              path + ": config key 'sweep_interval_s': expected a number of seconds, got string");
  }
}

}  // namespace
}  // namespace agnocastd
