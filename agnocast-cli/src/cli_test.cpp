// run_cli end to end against a fake system: output forms and exit codes.
#include "cli.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "agnocast/status.hpp"
#include "commands.hpp"
#include "fake_source.hpp"

namespace agnocast::cli {
namespace {

struct Outcome {
  int code;
  std::string out;
  std::string err;
};

Outcome run(FakeSource& source, std::vector<const char*> args) {
  args.insert(args.begin(), "agnocast-cli");
  std::ostringstream out, err;
  const int code = run_cli(static_cast<int>(args.size()), args.data(), source, out, err);
  return {code, out.str(), err.str()};
}

TEST(Cli, TableByDefault) {
  FakeSource source = healthy_system();
  const Outcome r = run(source, {"topic", "list"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind("NAME", 0), 0u);
  EXPECT_EQ(r.err, "");
}

TEST(Cli, JsonGlobalOrPerSubcommandPrintsExactlyOneObject) {
  for (auto args : {std::vector<const char*>{"--json", "topic", "list"},
                    std::vector<const char*>{"topic", "list", "--json"}}) {
    FakeSource source = healthy_system();
    const Outcome r = run(source, args);
    EXPECT_EQ(r.code, 0);
    ASSERT_FALSE(r.out.empty());
    EXPECT_EQ(r.out.back(), '\n');
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1);  // one line: one object
    EXPECT_TRUE(nlohmann::json::parse(r.out).contains("topics"));
  }
}

TEST(Cli, EveryCommandRunsOnAHealthySystem) {
  const std::vector<std::vector<const char*>> commands = {
      {"topic", "list"},
      {"topic", "info", "/chatter"},
      {"topic", "hz", "/chatter", "--count", "1"},
      {"node", "info", "talker"},
      {"process", "list"},
      {"queue", "list"},
      {"node", "list"},
      {"daemon", "status"},
      {"doctor"},
      {"policy", "show"},
      {"service", "list"},
      {"version"}};
  for (const auto& command : commands) {
    for (bool json : {false, true}) {
      FakeSource source = healthy_system();
      auto args = command;
      if (json) args.push_back("--json");
      const Outcome r = run(source, args);
      EXPECT_EQ(r.code, 0) << command[0] << ": " << r.err;
      if (json) {
        EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;
      }
    }
  }
}

TEST(Cli, UsageErrorsExitTwo) {
  FakeSource source = healthy_system();
  for (auto args : {std::vector<const char*>{}, std::vector<const char*>{"frobnicate"},
                    std::vector<const char*>{"topic"}, std::vector<const char*>{"topic", "info"},
                    std::vector<const char*>{"topic", "info", "no-slash"},
                    std::vector<const char*>{"topic", "hz", "/chatter", "--window", "-1"},
                    std::vector<const char*>{"version", "--bogus"}}) {
    const Outcome r = run(source, args);
    EXPECT_EQ(r.code, 2) << (args.empty() ? "" : args[0]);
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("agnocast-cli: "), std::string::npos);
  }
}

TEST(Cli, AnUnknownCommandIsNamedWithTheValidOnes) {
  FakeSource source = healthy_system();
  Outcome r = run(source, {"frobnicate"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown command 'frobnicate' for 'agnocast-cli'; valid commands: topic, "
                       "service, queue, node, process, daemon, doctor, policy, version"),
            std::string::npos)
      << r.err;
  r = run(source, {"--json", "topic", "lsit"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown command 'lsit' for 'agnocast-cli topic'; valid commands: list, "
                       "info, hz, delay, echo"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["exit_code"], 2);
  r = run(source, {"topic"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("'agnocast-cli topic' needs a command: list, info, hz, delay, echo"),
            std::string::npos)
      << r.err;
}

TEST(Cli, VersionFlagIsTheVersionCommand) {
  FakeSource source = healthy_system();
  const Outcome command = run(source, {"version", "--json"});
  const Outcome flag = run(source, {"--version", "--json"});
  EXPECT_EQ(flag.code, 0) << flag.err;
  EXPECT_EQ(flag.out, command.out);
  EXPECT_EQ(run(source, {"--json", "--version"}).out, command.out);
  EXPECT_EQ(run(source, {"--version"}).out, run(source, {"version"}).out);
}

TEST(Cli, UsageErrorWithJsonPrintsAnErrorObject) {
  FakeSource source = healthy_system();
  const Outcome r = run(source, {"--json", "topic", "info"});
  EXPECT_EQ(r.code, 2);
  const auto value = nlohmann::json::parse(r.out);
  EXPECT_EQ(value["exit_code"], 2);
  EXPECT_TRUE(value["error"].is_string());
}

TEST(Cli, HelpExitsZero) {
  FakeSource source = healthy_system();
  const Outcome r = run(source, {"topic", "info", "--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("TOPIC"), std::string::npos);
}

TEST(Cli, ModuleNotLoadedExitsOneNamingTheFix) {
  FakeSource source = healthy_system();
  source.loaded = false;
  const Outcome r = run(source, {"topic", "list"});
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("systemctl start agnocastd"), std::string::npos);
}

TEST(Cli, RuntimeErrorWithJsonPrintsOnlyAnErrorObject) {
  FakeSource source = healthy_system();
  const Outcome r = run(source, {"--json", "topic", "info", "/nope"});
  EXPECT_EQ(r.code, 1);
  const auto value = nlohmann::json::parse(r.out);
  EXPECT_EQ(value["exit_code"], 1);
  EXPECT_NE(value["error"].get<std::string>().find("/nope"), std::string::npos);
}

TEST(Cli, DoctorExitsOneWhenACheckFailsButStillPrintsTheChecks) {
  FakeSource source = healthy_system();
  source.loaded = false;
  source.paths.clear();
  const Outcome r = run(source, {"doctor", "--json"});
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(nlohmann::json::parse(r.out)["checks"].size(), 6u);
  const Outcome table = run(source, {"doctor"});
  EXPECT_EQ(table.code, 1);
  EXPECT_NE(table.out.find("FAIL"), std::string::npos);
}

TEST(Cli, DaemonNotRunningExitsZeroWithAHint) {
  FakeSource source = healthy_system();
  source.locks["/run/agnocast/agnocastd.lock"] = false;
  const Outcome r = run(source, {"daemon", "status"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("running            no"), std::string::npos);
  EXPECT_NE(r.err.find("systemctl start agnocastd"), std::string::npos);
}

TEST(Cli, DaemonStatusFileOption) {
  FakeSource source = healthy_system();
  source.files["/tmp/d.json"] = source.files["/run/agnocast/agnocastd.json"];
  source.locks["/tmp/agnocastd.lock"] = true;
  source.files.erase("/run/agnocast/agnocastd.json");
  const Outcome r = run(source, {"daemon", "status", "--status-file", "/tmp/d.json", "--json"});
  EXPECT_TRUE(nlohmann::json::parse(r.out)["running"].get<bool>());
}

TEST(Cli, DaemonStatusShowsTheBridgeAndFoxgloveFromTheirFiles) {
  FakeSource source = healthy_system();
  source.files["/tmp/b.json"] = to_json(
      ServiceStatus{"agnocast-bridge", 60, "0.1.0", ServiceState::running, 1700000000, 1, 1});
  source.locks["/tmp/b.lock"] = true;
  const Outcome r = run(source, {"daemon", "status", "--bridge-status-file", "/tmp/b.json",
                                 "--foxglove-status-file", "/tmp/none.json", "--json"});
  EXPECT_EQ(r.code, 0);
  const auto value = nlohmann::json::parse(r.out);
  EXPECT_TRUE(value["running"].get<bool>());
  EXPECT_EQ(value["bridge"]["pid"], 60);
  EXPECT_FALSE(value["foxglove"]["running"].get<bool>());
  const Outcome table = run(source, {"daemon", "status", "--bridge-status-file", "/tmp/b.json"});
  EXPECT_NE(table.out.find("agnocast-bridge    yes"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("agnocast-foxglove  no"), std::string::npos) << table.out;
  EXPECT_EQ(table.err, "");  // only a stopped agnocastd is worth a hint
}

TEST(Cli, ServiceCommandsTableAndJson) {
  FakeSource source = system_with_service();
  Outcome r = run(source, {"service", "list"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("NAME         TYPE                  SERVER  CLIENTS\n", 0), 0u) << r.out;
  r = run(source, {"--json", "service", "list"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out), service_list_json(source));
  r = run(source, {"service", "info", "/arm/enable", "--json"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out), service_info_json(source, "/arm/enable"));
  r = run(source, {"service", "info", "/arm/enable"});
  EXPECT_EQ(r.out, service_info_table(service_info_json(source, "/arm/enable")));
  r = run(source, {"service", "type", "/arm/enable"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "std_srvs/srv/SetBool\n");
  r = run(source, {"service", "type", "/arm/enable", "--json"});
  EXPECT_EQ(nlohmann::json::parse(r.out)["type"], "std_srvs/srv/SetBool");
}

TEST(Cli, AnUnknownServiceExitsOne) {
  FakeSource source = system_with_service();
  for (const char* command : {"info", "type"}) {
    Outcome r = run(source, {"service", command, "/nope"});
    EXPECT_EQ(r.code, 1) << command;
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("no server or client uses service '/nope'"), std::string::npos) << r.err;
    r = run(source, {"--json", "service", command, "/nope"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(nlohmann::json::parse(r.out)["exit_code"], 1);
  }
}

TEST(Cli, BadServiceInputIsAUsageError) {
  FakeSource source = system_with_service();
  const std::vector<std::vector<const char*>> commands = {
      {"service"},
      {"service", "info"},
      {"service", "type"},
      {"service", "info", "arm/enable"},
      {"service", "info", "/arm//enable"},
      {"service", "type", "/arm enable"},
      {"service", "info", "/_service_request/arm/enable"},
      {"service", "info", "/arm/enable", "/extra"},
      {"service", "list", "--bogus"},
      {"service", "info", "/arm/enable", "--count", "1"},
      {"service", "call", "/arm/enable"},
      {"service", "lsit"}};
  for (const auto& args : commands) {
    const Outcome r = run(source, args);
    EXPECT_EQ(r.code, 2) << args.back();
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("agnocast-cli: "), std::string::npos);
  }
  Outcome r = run(source, {"service", "info", "/_service_reply/x"});
  EXPECT_NE(r.err.find("must not start with /_service_request or /_service_reply"),
            std::string::npos)
      << r.err;
  r = run(source, {"service", "lsit"});
  EXPECT_NE(r.err.find("unknown command 'lsit' for 'agnocast-cli service'; valid commands: list, "
                       "info, type"),
            std::string::npos)
      << r.err;
  r = run(source, {"--json", "service", "info", "bad"});
  EXPECT_EQ(nlohmann::json::parse(r.out)["exit_code"], 2);
}

TEST(Cli, TopicEchoRefusesATopicThatCarriesAService) {
  FakeSource source = system_with_service();
  const Outcome r = run(source, {"topic", "echo", "/_service_reply/arm/enable", "--count", "1"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("carries the responses of service '/arm/enable'"), std::string::npos)
      << r.err;
}

TEST(Cli, ServiceTopicsAreLeftOutOfTopicAndQueueLists) {
  FakeSource source = system_with_service();
  for (const char* command : {"topic", "queue"}) {
    const Outcome r = run(source, {command, "list"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.out.find("_service_"), std::string::npos) << r.out;
    const Outcome json = run(source, {command, "list", "--json"});
    EXPECT_EQ(json.out.find("_service_"), std::string::npos) << json.out;
  }
}

}  // namespace
}  // namespace agnocast::cli
