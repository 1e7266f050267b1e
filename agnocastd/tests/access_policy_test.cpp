// agnocastd's topic access policy in the VM: loaded at start, enforced by the
// kernel for processes of other users and groups, shown by agnocast-cli,
// replaced on SIGHUP without disturbing existing endpoints, and kept when the
// new file is bad.
#include <fcntl.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <agnocast/status.hpp>
#include <agnocast_test/process.hpp>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "chatter_message.hpp"

namespace {

using agnocast_test::become;
using agnocast_test::eventually;
using agnocast_test::Identity;
using agnocast_test::slurp;
using agnocast_test::spawn;
using agnocast_test::vm_agnocast_gid;
using agnocast_test::wait_exit;
using agnocast_test::write_file;
using nlohmann::json;
using namespace std::chrono_literals;

constexpr gid_t safety_gid = 3000;  // no name: the config uses "group:3000"

const Identity safety_member{2001, 2001, {vm_agnocast_gid, safety_gid}};
const Identity outsider{2002, 2002, {vm_agnocast_gid}};

// How long the daemon, the endpoints and a reload may take.
constexpr std::chrono::seconds patience = 10s;

// The topics' type: the talker's and listener's message.
using Sample = chatter::Message;

enum class Direction { publish, subscribe };
constexpr int created = 0;
constexpr int denied = 10;

// Whether `who` may create the endpoint; for a refusal, what() lands in `why`.
int try_endpoint(const Identity& who, Direction direction, const std::string& topic,
                 std::string* why = nullptr) {
  const std::string log = "endpoint.log";
  const pid_t pid = ::fork();
  if (pid == 0) {
    // Opened before dropping root: the test's directory is root's.
    std::ofstream reason(log);
    become(who);
    try {
      agnocast::Node node{"probe"};
      if (direction == Direction::publish) {
        node.create_publisher<Sample>(topic, agnocast::QoS{1});
      } else {
        node.create_subscription<Sample>(topic, agnocast::QoS{1},
                                         [](const agnocast::ipc_shared_ptr<const Sample>&) {});
      }
      ::_exit(created);
    } catch (const agnocast::AccessDenied& error) {
      reason << error.what() << std::flush;
      ::_exit(denied);
    } catch (const std::exception& error) {
      reason << error.what() << std::flush;
      ::_exit(20);
    }
  }
  const int code = wait_exit(pid);
  if (why) *why = slurp(log);
  return code;
}

// The JSON value `agnocast-cli ARGS --json` prints; null when it fails.
json cli_json(const Identity* who, const std::vector<std::string>& args) {
  std::vector<std::string> command{"agnocast-cli"};
  command.insert(command.end(), args.begin(), args.end());
  command.push_back("--json");
  const int code = wait_exit(spawn(command, "cli.out", who));
  const std::string out = slurp("cli.out");
  return code == 0 && json::accept(out) ? json::parse(out) : json();
}

std::string last_line(const std::string& text) {
  const auto end = text.find_last_not_of('\n');
  if (end == std::string::npos) return {};
  const auto start = text.rfind('\n', end);
  return text.substr(start == std::string::npos ? 0 : start + 1, end + 1 - (start + 1));
}

json policy_shown(const Identity* who) { return cli_json(who, {"policy", "show"}); }

bool log_has(const std::string& text) {
  return slurp("agnocastd.log").find(text) != std::string::npos;
}

std::size_t occurrences(const std::string& text) {
  const std::string log = slurp("agnocastd.log");
  std::size_t count = 0;
  for (auto at = log.find(text); at != std::string::npos; at = log.find(text, at + 1)) ++count;
  return count;
}

bool daemon_ready(pid_t daemon) {
  const std::string status = slurp(std::string(agnocast::daemon_status_path));
  if (!json::accept(status)) return false;
  const json value = json::parse(status);
  return value.value("pid", 0) == daemon && value.value("running", false);
}

const char* policy_a = R"({"device": {"group": "agnocast"}, "sweep_interval_s": 1,
  "access": {"default": "allow", "rules": [
    {"topics": "/safety/**", "publish": ["group:3000"], "subscribe": ["group:agnocast"]}]}})";
const char* policy_b = R"({"device": {"group": "agnocast"}, "sweep_interval_s": 1,
  "access": {"default": "deny", "rules": [
    {"topics": "/safety/**", "publish": ["user:2002"], "subscribe": ["*"]},
    {"services": "/arm/*", "serve": ["user:2002"], "call": ["*"]}]}})";
const char* bad_policy = R"({"device": {"group": "agnocast"},
  "access": {"rules": [{"topics": "/safety/**", "publish": ["group:no_such_group_zz"]}]}})";

TEST(AccessPolicy, EnforcedShownAndReplacedOnSighup) {
  write_file("agnocastd.json", policy_a);
  const pid_t daemon = spawn({"agnocastd", "--config", "agnocastd.json"}, "agnocastd.log");
  ASSERT_TRUE(eventually([&] { return daemon_ready(daemon); }, patience)) << slurp("agnocastd.log");

  // Policy A: only group 3000 publishes /safety/**; the default allows the rest.
  std::string why;
  EXPECT_EQ(try_endpoint(safety_member, Direction::publish, "/safety/brake"), created);
  EXPECT_EQ(try_endpoint(outsider, Direction::publish, "/safety/brake", &why), denied) << why;
  EXPECT_NE(why.find("/safety/brake"), std::string::npos) << why;
  EXPECT_EQ(try_endpoint(outsider, Direction::subscribe, "/safety/brake"), created);
  EXPECT_EQ(try_endpoint(outsider, Direction::publish, "/other"), created);
  const json shown_a = json::parse(R"({"policy": {"default": "allow", "rules": [
    {"topics": "/safety/**", "publish": ["group:3000"], "subscribe": ["group:agnocast"]}]}})");
  EXPECT_EQ(policy_shown(&outsider), shown_a);  // unprivileged, in group agnocast
  EXPECT_EQ(policy_shown(nullptr), shown_a);

  // Endpoints made under policy A, kept across the reload.
  const pid_t talker =
      spawn({"agnocast-talker", "--topic", "/safety/brake", "--rate", "100", "--linger", "0"},
            "talker.log", &safety_member);
  const pid_t listener = spawn({"agnocast-listener", "--topic", "/safety/brake", "--json"},
                               "listener.log", &safety_member);
  const auto published = [] {
    const json info = cli_json(nullptr, {"topic", "info", "/safety/brake"});
    return info.is_object() && !info["publishers"].empty()
               ? info["publishers"][0].value("published", std::uint64_t{0})
               : std::uint64_t{0};
  };
  ASSERT_TRUE(eventually([&] { return published() > 20; }, patience)) << slurp("talker.log");

  // Policy B: only user 2002 publishes /safety/**; the default denies the rest.
  write_file("agnocastd.json", policy_b);
  ::kill(daemon, SIGHUP);
  ASSERT_TRUE(eventually([] { return log_has("configuration reloaded"); }, patience))
      << slurp("agnocastd.log");
  const std::uint64_t published_at_reload = published();
  // The services rule went into the kernel as two topic rules and shows as written.
  EXPECT_EQ(policy_shown(&outsider), json::parse(R"({"policy": {"default": "deny", "rules": [
    {"topics": "/safety/**", "publish": ["user:2002"], "subscribe": ["*"]},
    {"services": "/arm/*", "serve": ["user:2002"], "call": ["*"]}]}})"));
  EXPECT_TRUE(log_has("access policy in force: 1 topics rule(s), 1 services rule(s), default deny"))
      << slurp("agnocastd.log");
  EXPECT_EQ(try_endpoint(safety_member, Direction::publish, "/safety/brake", &why), denied) << why;
  EXPECT_EQ(try_endpoint(outsider, Direction::publish, "/safety/brake", &why), created) << why;
  EXPECT_EQ(try_endpoint(safety_member, Direction::subscribe, "/safety/brake"), created);
  EXPECT_EQ(try_endpoint(outsider, Direction::publish, "/other", &why), denied) << why;
  EXPECT_NE(why.find("/other"), std::string::npos) << why;

  // A bad file: logged, and policy B stays.
  write_file("agnocastd.json", bad_policy);
  ::kill(daemon, SIGHUP);
  ASSERT_TRUE(eventually([] { return log_has("no group named 'no_such_group_zz'"); }, patience))
      << slurp("agnocastd.log");
  EXPECT_TRUE(log_has("[error] configuration not reloaded")) << slurp("agnocastd.log");
  EXPECT_EQ(occurrences("configuration reloaded"), 1u);
  EXPECT_EQ(policy_shown(nullptr)["policy"]["default"], "deny");
  EXPECT_EQ(try_endpoint(safety_member, Direction::publish, "/safety/brake"), denied);
  EXPECT_EQ(try_endpoint(outsider, Direction::publish, "/safety/brake"), created);

  // The talker and listener of policy A kept working: messages published
  // after the reload reached the listener.
  ASSERT_TRUE(eventually([&] { return published() > published_at_reload + 50; }, patience));
  ::kill(listener, SIGINT);
  EXPECT_EQ(wait_exit(listener), 0) << slurp("listener.log");
  ::kill(talker, SIGINT);
  EXPECT_EQ(wait_exit(talker), 0) << slurp("talker.log");
  const std::string summary = last_line(slurp("listener.log"));
  ASSERT_TRUE(json::accept(summary)) << summary;
  const json received = json::parse(summary);
  EXPECT_EQ(received["corrupt"], 0);
  EXPECT_GT(received["last_seq"].get<std::uint64_t>(), published_at_reload + 40) << summary;

  ::kill(daemon, SIGTERM);
  EXPECT_EQ(wait_exit(daemon), 0) << slurp("agnocastd.log");
}

}  // namespace
