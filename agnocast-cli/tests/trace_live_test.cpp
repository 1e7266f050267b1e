// agnocast-cli trace record and trace report in the VM, with LTTng's own
// tools (lttng, lttng-sessiond, babeltrace2, Debian's): the PointCloud2
// pipeline (driver -> filter -> consumer, three processes, started while the
// system's session daemon runs) traced from before its first message to
// after its last; a recording that starts its own session daemon, through
// which processes are killed, beside one that started before any daemon and
// so carries no probes; and a user without permission.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast_test/process.hpp>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

namespace {

using agnocast_test::eventually;
using agnocast_test::slurp;
using agnocast_test::spawn;
using agnocast_test::stop;
using nlohmann::json;
using namespace std::chrono_literals;

agnocast_test::Outcome cli(const std::string& args, const std::string& stem = "cli") {
  return agnocast_test::run_shell("agnocast-cli " + args, stem);
}

// Under TCG processes take seconds to start.
constexpr auto patience = 60s;

bool subscribed(const std::string& topic) {
  const auto info = cli("topic info " + topic + " --json", "info");
  return info.code == 0 && !json::parse(info.out)["subscribers"].empty();
}

// The exit status of `pid` once it ended within `limit`; -1 (and killed) when it did not.
int exit_within(pid_t pid, std::chrono::seconds limit) {
  int status = 0;
  const bool ended = eventually([&] { return ::waitpid(pid, &status, WNOHANG) == pid; }, limit);
  if (!ended) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Starts `trace record` and waits until its LTTng session runs.
pid_t start_recording(const std::vector<std::string>& extra, const std::string& stem) {
  std::vector<std::string> args = {"agnocast-cli", "trace", "record", "--json"};
  args.insert(args.end(), extra.begin(), extra.end());
  const pid_t recorder = spawn(args, stem + ".out", stem + ".err");
  const bool running = eventually(
      [] {
        return agnocast_test::run_shell("lttng --no-sessiond list | grep -q agnocast-cli-", "lttng")
                   .code == 0;
      },
      patience, 200ms);
  EXPECT_TRUE(running) << slurp(stem + ".out") << slurp(stem + ".err");
  // The processes already running register with the session daemon it started.
  std::this_thread::sleep_for(3s);
  return recorder;
}

// Whether a live process (not a zombie: orphans the VM's init has not
// reaped are gone) runs one of `names`.
bool running(std::initializer_list<std::string> names) {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string stat = slurp(entry.path() / "stat");
    const auto open = stat.find('('), close = stat.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close + 2 >= stat.size()) {
      continue;
    }
    const std::string name = stat.substr(open + 1, close - open - 1);
    for (const std::string& wanted : names) {
      // /proc truncates a command name to 15 characters.
      if (name == wanted.substr(0, 15) && stat[close + 2] != 'Z') return true;
    }
  }
  return false;
}

// Waits for `trace record` (stem.out, stem.err) to end, which it must with
// exit 0, and returns its summary; `recorder` becomes -1.
json finished_recording(pid_t& recorder, const std::string& stem) {
  const int code = exit_within(recorder, 120s);
  recorder = -1;
  EXPECT_EQ(code, 0) << slurp(stem + ".err");
  if (code != 0) return nullptr;
  const json summary = json::parse(slurp(stem + ".out"));
  std::cout << "trace record: " << summary.dump() << "\n";
  return summary;
}

// The system's session daemon, as `systemctl start lttng-sessiond` runs it.
pid_t start_session_daemon() {
  const pid_t daemon = spawn({"lttng-sessiond", "--no-kernel"}, "sessiond.log");
  EXPECT_TRUE(eventually(
      [] { return agnocast_test::run_shell("lttng --no-sessiond list", "lttng-list").code == 0; },
      patience))
      << slurp("sessiond.log");
  return daemon;
}

void expect_nothing_left() {
  EXPECT_TRUE(eventually(
      [] {
        return !running({"lttng-sessiond", "lttng-consumerd"});
      },
      patience))
      << "a session daemon outlived trace record";
  for (const auto& entry : std::filesystem::directory_iterator("/sys/kernel/tracing/instances")) {
    EXPECT_EQ(entry.path().filename().string().rfind("agnocast-cli-", 0), std::string::npos)
        << entry.path() << " left behind";
  }
  for (const auto& entry : std::filesystem::directory_iterator("/tmp")) {
    EXPECT_EQ(entry.path().filename().string().rfind("agnocast-trace-", 0), std::string::npos)
        << entry.path() << " left behind";
  }
}

// What a test started, ended however the test ends, so that the next test
// starts clean.
struct Started {
  std::deque<pid_t> children;  // a deque: add() hands out references that stay valid
  ~Started() {
    for (pid_t& child : children) stop(child);
  }
  pid_t& add(pid_t child) { return children.emplace_back(child); }
};

class TraceLive : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // The VM's init sets no HOME; LTTng's tools read their settings there.
    ::setenv("HOME", "/tmp", 0);
    // Nor /var/run, where the system's session daemon keeps its sockets.
    if (!std::filesystem::exists("/var/run")) {
      std::filesystem::create_directories("/var");
      std::filesystem::create_directory_symlink("/run", "/var/run");
    }
    if (!std::filesystem::exists("/sys/kernel/tracing/events")) {
      ::mount("tracefs", "/sys/kernel/tracing", "tracefs", 0, nullptr);
    }
  }
};

TEST_F(TraceLive, EveryMessageOfAPipelineFlowsToItsCallbacksAndTheReportAgreesWithTopicDelay) {
  const std::string raw = "/trace/points_raw", filtered = "/trace/points_filtered";
  constexpr int scans = 50;
  Started started;
  pid_t& session_daemon = started.add(start_session_daemon());
  // Alive until the end: topic delay shows the subscribers its window ends with.
  started.add(
      spawn({"agnocast-pointcloud-consumer", "--topic", filtered, "--count", "0", "--timeout",
             "300", "--min-range", "1.5", "--max-range", "6.5", "--depth", "100"},
            "consumer.out", "consumer.err"));
  ASSERT_TRUE(eventually([&] { return subscribed(filtered); }, patience));
  pid_t& filter =
      started.add(spawn({"agnocast-pointcloud-filter", "--input", raw, "--output", filtered,
                         "--min-range", "1.5", "--max-range", "6.5", "--depth", "100"},
                        "filter.log"));
  ASSERT_TRUE(eventually([&] { return subscribed(raw); }, patience));

  pid_t& recorder = started.add(start_recording({"-o", "pipeline.json"}, "record"));
  // topic delay over the same messages, from what the consumer records.
  const pid_t delay = spawn(
      {"agnocast-cli", "topic", "delay", filtered, "--window", "15", "--count", "1", "--json"},
      "delay.out", "delay.err");
  const pid_t driver =
      spawn({"agnocast-pointcloud-driver", "--topic", raw, "--count", std::to_string(scans),
             "--rate", "10", "--points", "1000", "--depth", "100"},
            "driver.log");
  EXPECT_EQ(exit_within(driver, 120s), 0) << slurp("driver.log");
  // The window outlasts the driver: every scan has reached the consumer by its end.
  EXPECT_EQ(exit_within(delay, 120s), 0) << slurp("delay.err");
  ::kill(recorder, SIGINT);
  const json summary = finished_recording(recorder, "record");
  ASSERT_FALSE(summary.is_null());
  stop(filter);

  EXPECT_EQ(summary["kernel"], true);
  EXPECT_EQ(summary["counts"], true);
  EXPECT_GE(summary["flows"].get<int>(), 2 * scans);

  // The file: every publish of the pipeline's topics has its flow to the
  // one subscriber, the flow starts before it ends, slices and tracks named.
  const json trace = json::parse(slurp("pipeline.json"));
  std::map<std::uint64_t, json> starts;
  std::map<std::string, int> flows, publishes, kernel_publishes;
  int counters = 0;
  for (const json& event : trace["traceEvents"]) {
    const std::string phase = event["ph"];
    if (phase == "s") starts[event["id"]] = event;
    if (phase == "f") {
      const json& start = starts.at(event["id"]);
      EXPECT_LE(start["ts"].get<double>(), event["ts"].get<double>());
      ++flows[event["name"]];
    }
    if (phase == "X" && event["cat"] == "publish") ++publishes[event["args"]["topic"]];
    if (phase == "i" && event["name"] == "kernel publish " + raw) ++kernel_publishes[raw];
    if (phase == "C") ++counters;
  }
  EXPECT_EQ(publishes[raw], scans);
  EXPECT_EQ(publishes[filtered], scans);
  EXPECT_EQ(flows[raw], scans);
  EXPECT_EQ(flows[filtered], scans);
  EXPECT_EQ(kernel_publishes[raw], scans);
  EXPECT_GT(counters, 0);

  const auto report =
      cli("trace report pipeline.json --path " + raw + "," + filtered + " --json", "report");
  ASSERT_EQ(report.code, 0) << report.err;
  const json value = json::parse(report.out);
  std::cout << "trace report: " << value.dump() << "\n";
  EXPECT_EQ(value["path"]["count"], scans);
  EXPECT_EQ(value["path"]["incomplete"], 0);
  json consumer_row;
  for (const json& row : value["topics"]) {
    if (row["topic"] == filtered) consumer_row = row;
  }
  ASSERT_FALSE(consumer_row.is_null());
  EXPECT_EQ(consumer_row["count"], scans);
  EXPECT_EQ(consumer_row["node"], "pointcloud_consumer");

  // topic delay timed the same callbacks from the publish time the library
  // stamps just before PUBLISH; the trace's publish event follows PUBLISH.
  const json delays = json::parse(slurp("delay.out"));
  const json& row = delays["subscribers"].at(0);
  ASSERT_FALSE(row["p50_us"].is_null()) << delays.dump();
  const double from_delay = row["p50_us"], from_trace = consumer_row["p50_us"];
  std::cout << "p50 publish -> callback start: topic delay " << from_delay << " us, trace "
            << from_trace << " us\n";
  // Under TCG that system call takes up to a few hundred microseconds: the
  // trace's figure runs that much shorter.
  EXPECT_LE(std::fabs(from_delay - from_trace), 0.3 * from_delay + 100)
      << "topic delay and the trace disagree";
  stop(session_daemon);
  expect_nothing_left();
}

TEST_F(TraceLive, ProcessesKilledWhileRecordingLeaveAValidTrace) {
  const std::string topic = "/trace/dying";
  Started started;
  // Started while no session daemon runs: no probes, named as silent.
  pid_t& early = started.add(
      spawn({"agnocast-listener", "--topic", "/trace/early", "--count", "0"}, "early.log"));
  ASSERT_TRUE(eventually([&] { return subscribed("/trace/early"); }, patience));
  pid_t& recorder = started.add(start_recording({"--duration", "8", "-o", "dying.json"}, "dying"));
  pid_t& listener = started.add(spawn(
      {"agnocast-listener", "--topic", topic, "--count", "0", "--depth", "10"}, "listener.log"));
  ASSERT_TRUE(eventually([&] { return subscribed(topic); }, patience));
  pid_t& talker = started.add(
      spawn({"agnocast-talker", "--topic", topic, "--count", "0", "--rate", "50"}, "talker.log"));
  std::this_thread::sleep_for(2s);
  ::kill(talker, SIGKILL);  // mid-publish, perhaps
  ::waitpid(talker, nullptr, 0);
  talker =
      spawn({"agnocast-talker", "--topic", topic, "--count", "0", "--rate", "50"}, "talker2.log");
  std::this_thread::sleep_for(2s);
  ::kill(listener, SIGKILL);  // mid-callback, perhaps
  ::waitpid(listener, nullptr, 0);
  listener = -1;
  const json summary = finished_recording(recorder, "dying");
  ASSERT_FALSE(summary.is_null());
  stop(talker);
  EXPECT_GT(summary["flows"].get<int>(), 0);
  EXPECT_EQ(summary["silent_pids"], json::array({early}));
  const auto report = cli("trace report dying.json --json", "dying-report");
  EXPECT_EQ(report.code, 0) << report.err;
  EXPECT_FALSE(json::parse(report.out)["topics"].empty());
  expect_nothing_left();
}

TEST_F(TraceLive, AUserOutsideTheTracingGroupIsToldWhatIsMissing) {
  const agnocast_test::Identity nobody{1000, 1000, {agnocast_test::vm_agnocast_gid}};
  const auto outcome = agnocast_test::run_shell(
      "agnocast-cli trace record --duration 1 -o /tmp/x.json", "nobody", &nobody);
  EXPECT_EQ(outcome.code, 1);
  EXPECT_NE(outcome.err.find("tracing group"), std::string::npos) << outcome.err;
  EXPECT_FALSE(std::filesystem::exists("/tmp/x.json"));
}

}  // namespace
