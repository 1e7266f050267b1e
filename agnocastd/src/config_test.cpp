#include "config.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

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
      error_of(R"({"access": {"rules": [{"topics": "/a", "publish": ["user:4294967295"]}]}})"),
      "config key 'access.rules[0].publish[0]': id 4294967295 is out of range");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "publish": "group:root"}]}})"),
            "config key 'access.rules[0].publish': expected an array of \"user:NAME\", "
            "\"group:NAME\" or \"*\", got string");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"topics": "/a", "publish": [0]}]}})"),
            "config key 'access.rules[0].publish[0]': expected a string, got number");
  EXPECT_EQ(error_of(R"({"access": {"rules": [{"publish": []}]}})"),
            "config key 'access.rules[0]': a rule needs \"topics\", the topic pattern it covers");
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
