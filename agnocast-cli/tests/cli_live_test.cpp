// agnocast-cli against a live system in the VM: a talker, a listener, a
// stopped listener (wake-once: one wake-up pending, its unreceived entries
// growing to its depth; then resumed, missing none of them) and a hand-made
// stale queue /ghost@7. Every command's table and JSON are checked, the exit
// codes 0/1/2, and, last, doctor failing once the module is removed.
#include <fcntl.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <mqueue.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast_test/process.hpp>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using agnocast_test::become;
using agnocast_test::eventually;
using agnocast_test::slurp;
using agnocast_test::spawn;
using agnocast_test::stop;
using agnocast_test::vm_agnocast_gid;
using nlohmann::json;

struct Outcome : agnocast_test::Outcome {
  json value() const { return json::parse(out); }
};

// Runs agnocast-cli ARGS through sh, as root or, with `uid`, as that user
// with only the supplementary `groups`.
Outcome cli(const std::string& args, uid_t uid = 0, const std::vector<gid_t>& groups = {}) {
  const agnocast_test::Identity who{uid, uid, groups};
  return {agnocast_test::run_shell("agnocast-cli " + args, "cli-" + std::to_string(uid),
                                   uid != 0 ? &who : nullptr)};
}

// Under TCG the daemon and the endpoints take seconds to come up.
constexpr std::chrono::seconds patience{30};

// The element of `array` whose `key` equals `wanted`, or null.
json find_by(const json& array, const std::string& key, const json& wanted) {
  for (const json& item : array) {
    if (item.at(key) == wanted) return item;
  }
  return nullptr;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> words_of(const std::string& line) {
  std::vector<std::string> words;
  std::istringstream in(line);
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

// The table row whose first word is `first` (after the header), split in words.
std::vector<std::string> row_starting(const std::string& table, const std::string& first) {
  for (const std::string& line : lines_of(table)) {
    const auto words = words_of(line);
    if (!words.empty() && words[0] == first) return words;
  }
  return {};
}

// The table row containing `needle`, as is.
std::string line_containing(const std::string& table, const std::string& needle) {
  for (const std::string& line : lines_of(table)) {
    if (line.find(needle) != std::string::npos) return line;
  }
  return {};
}

// Right-aligned columns end where their header ends.
void expect_ends_under_header(const std::string& table, const std::string& header,
                              const std::string& row) {
  const std::string head = lines_of(table).at(0);
  const std::size_t end = head.find(header) + header.size();
  ASSERT_NE(head.find(header), std::string::npos) << head;
  ASSERT_FALSE(row.empty());
  EXPECT_TRUE(row.size() >= end && row[end - 1] != ' ' && (row.size() == end || row[end] == ' '))
      << "column " << header << " misaligned:\n"
      << head << "\n"
      << row;
}

// The notifications waiting in `queue` (its mq_curmsgs), read here, not
// through agnocast-cli; -1 if it cannot be opened.
long queued_notifications(const std::string& queue) {
  const mqd_t q = ::mq_open(queue.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (q == static_cast<mqd_t>(-1)) return -1;
  mq_attr attributes{};
  const int r = ::mq_getattr(q, &attributes);
  ::mq_close(q);
  return r == 0 ? attributes.mq_curmsgs : -1;
}

// A nested name, so queue names show the mangling ('/' -> '_').
const std::string topic = "/cli_live/chatter";
const std::string queue_prefix = "/cli_live_chatter@";

// The subscriber of `pid` in `topic info`, or null.
json subscriber_of(pid_t pid) {
  const Outcome r = cli("topic info " + topic + " --json");
  return r.code == 0 ? find_by(r.value()["subscribers"], "pid", pid) : json();
}

class CliLive : public ::testing::Test {
 protected:
  static inline pid_t listener = -1, stopped = -1, talker = -1;

  static void SetUpTestSuite() {
    listener = spawn({"agnocast-listener", "--topic", topic, "--node", "listener", "--depth", "10",
                      "--timeout", "600"},
                     "listener.log");
    stopped = spawn({"agnocast-listener", "--topic", topic, "--node", "stopped", "--depth", "10",
                     "--timeout", "600"},
                    "stopped.log");
    ASSERT_TRUE(eventually(
        [] {
          const Outcome r = cli("topic list --json");
          const json t = r.code == 0 ? find_by(r.value()["topics"], "name", topic) : json();
          return !t.is_null() && t["subscribers"] == 2;
        },
        patience))
        << "the listeners never subscribed";
    // Stopped once it has taken the notification it sends itself on
    // subscribing (twice empty, 100 ms apart): from then on only the talker
    // wakes it.
    ASSERT_TRUE(eventually(
        [] {
          const json s = subscriber_of(stopped);
          if (s.is_null() || queued_notifications(s["queue"].get<std::string>()) != 0) return false;
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          return queued_notifications(s["queue"].get<std::string>()) == 0;
        },
        patience))
        << "the listener to stop never took its own notification";
    ASSERT_EQ(::kill(stopped, SIGSTOP), 0);
    talker = spawn({"agnocast-talker", "--topic", topic, "--node", "talker", "--depth", "10",
                    "--rate", "50", "--size", "1000"},
                   "talker.log");
    // A queue of the agnocast pattern that no subscriber owns.
    const int ghost = ::open("/dev/mqueue/ghost@7", O_RDWR | O_CREAT, 0600);
    ASSERT_GE(ghost, 0) << "cannot create /dev/mqueue/ghost@7";
    ::close(ghost);
    // Let the stopped listener's entries pile up beyond its depth.  It is
    // wake-once: one notification waits for it however many entries do.
    ASSERT_TRUE(eventually(
        [] {
          const json s = subscriber_of(stopped);
          return !s.is_null() && s["unreceived"] == 10 && s["dropped"] > 0;
        },
        patience))
        << slurp("cli-0.out");
  }

  static void TearDownTestSuite() {
    stop(talker);
    stop(stopped);
    stop(listener);
  }
};

TEST_F(CliLive, TopicList) {
  const Outcome r = cli("topic list --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(find_by(r.value()["topics"], "name", topic), json({{"name", topic},
                                                               {"type", "chatter/msg/Message"},
                                                               {"publishers", 1},
                                                               {"subscribers", 2}}));

  const Outcome table = cli("topic list");
  ASSERT_EQ(table.code, 0);
  EXPECT_EQ(words_of(lines_of(table.out).at(0)),
            (std::vector<std::string>{"NAME", "TYPE", "PUBLISHERS", "SUBSCRIBERS"}));
  EXPECT_EQ(row_starting(table.out, topic),
            (std::vector<std::string>{topic, "chatter/msg/Message", "1", "2"}));
  expect_ends_under_header(table.out, "SUBSCRIBERS", line_containing(table.out, topic));
}

TEST_F(CliLive, TopicInfo) {
  const Outcome r = cli("--json topic info " + topic);
  ASSERT_EQ(r.code, 0) << r.err;
  const json info = r.value();
  EXPECT_EQ(info["name"], topic);
  EXPECT_EQ(info["type"], "chatter/msg/Message");
  EXPECT_EQ(info["type_hash"].get<std::string>().size(), 16u);
  ASSERT_EQ(info["publishers"].size(), 1u);
  const json pub = info["publishers"][0];
  EXPECT_EQ(pub["pid"], talker);
  EXPECT_EQ(pub["node"], "talker");
  EXPECT_EQ(pub["depth"], 10);
  EXPECT_EQ(pub["transient_local"], false);
  EXPECT_GT(pub["published"].get<int>(), 0);

  const json live = find_by(info["subscribers"], "pid", listener);
  const json frozen = find_by(info["subscribers"], "pid", stopped);
  ASSERT_FALSE(live.is_null());
  ASSERT_FALSE(frozen.is_null());
  EXPECT_EQ(live["node"], "listener");
  EXPECT_EQ(live["queue"], queue_prefix + live["id"].dump());
  EXPECT_EQ(frozen["node"], "stopped");
  EXPECT_EQ(frozen["queue"], queue_prefix + frozen["id"].dump());
  // pending is the queue's mq_curmsgs: one wake-up for all ten entries.
  EXPECT_EQ(frozen["pending"], 1);
  EXPECT_EQ(frozen["pending"], queued_notifications(frozen["queue"].get<std::string>()));
  EXPECT_EQ(frozen["unreceived"], 10);
  EXPECT_GT(frozen["dropped"].get<int>(), 0);
  EXPECT_EQ(live["uid"], 0);
  EXPECT_EQ(live["polling"], false);
  EXPECT_GT(live["received"].get<int>(), 0);
  EXPECT_EQ(frozen["received"], 0);
  for (const json& s : info["subscribers"]) {
    EXPECT_EQ(s.size(), 13u) << s.dump();
  }

  const Outcome table = cli("topic info " + topic);
  ASSERT_EQ(table.code, 0);
  EXPECT_EQ(lines_of(table.out).at(0), "topic " + topic);
  EXPECT_EQ(lines_of(table.out).at(1).rfind("type  chatter/msg/Message (", 0), 0u) << table.out;
  const auto talker_row = row_starting(table.out, pub["id"].dump());
  ASSERT_EQ(talker_row.size(), 7u) << table.out;
  EXPECT_EQ(talker_row[1], std::to_string(talker));
  EXPECT_EQ(talker_row[2], "0");
  EXPECT_EQ(talker_row[3], "talker");
  const auto frozen_row = row_starting(table.out, frozen["id"].dump());
  ASSERT_EQ(frozen_row.size(), 12u) << table.out;
  EXPECT_EQ(frozen_row[1], std::to_string(stopped));
  EXPECT_EQ(frozen_row[6], frozen["queue"]);
  EXPECT_EQ(frozen_row[7], "1");
  EXPECT_EQ(frozen_row[8], "10");
  EXPECT_NE(table.out.find("PENDING  UNRECEIVED  HELD  RECEIVED  DROPPED"), std::string::npos);
}

TEST_F(CliLive, TopicHzMeasuresRateJitterAndPayloadWithoutSubscribing) {
  const Outcome r = cli("topic hz " + topic + " --window 2 --count 2 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto windows = lines_of(r.out);
  ASSERT_EQ(windows.size(), 2u) << r.out;
  for (const auto& line : windows) {
    const json hz = json::parse(line);
    EXPECT_EQ(hz["name"], topic);
    EXPECT_GE(hz["window_s"].get<double>(), 2.0);
    // The talker publishes at 50 Hz: a period of 20 ms, give or take the VM.
    EXPECT_GT(hz["messages"].get<int>(), 20);
    EXPECT_GT(hz["rate_hz"].get<double>(), 10.0);
    EXPECT_LE(hz["min_s"].get<double>(), 0.021);
    EXPECT_GE(hz["max_s"].get<double>(), 0.019);
    EXPECT_GE(hz["std_dev_s"].get<double>(), 0.0);
    EXPECT_LE(hz["min_s"].get<double>(), hz["max_s"].get<double>());
    // Payload bytes: each message carries its 1000-byte payload besides the
    // message object, so more than 1000 bytes per message are counted.
    EXPECT_GT(hz["bytes"].get<std::uint64_t>(), 1000u * hz["messages"].get<std::uint64_t>());
  }
  EXPECT_EQ(find_by(cli("topic list --json").value()["topics"], "name", topic)["subscribers"], 2);

  const Outcome table = cli("topic hz " + topic + " --window 1 --count 1");
  ASSERT_EQ(table.code, 0);
  EXPECT_EQ(row_starting(table.out, "RATE_HZ"),
            (std::vector<std::string>{"RATE_HZ", "MIN_S", "MAX_S", "STD_DEV_S", "BYTES_PER_S",
                                      "MESSAGES", "PUBLISHERS"}));
  EXPECT_EQ(lines_of(table.out).size(), 2u) << table.out;
}

TEST_F(CliLive, TopicDelayShowsEachCallbackSubscribersDelayFromPublish) {
  const Outcome r = cli("topic delay " + topic + " --window 2 --count 1 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(lines_of(r.out).size(), 1u) << r.out;
  const json window = json::parse(r.out);
  EXPECT_EQ(window["name"], topic);
  EXPECT_GE(window["window_s"].get<double>(), 2.0);
  ASSERT_EQ(window["subscribers"].size(), 2u) << r.out;
  const json live = find_by(window["subscribers"], "pid", listener);
  ASSERT_FALSE(live.is_null()) << r.out;
  EXPECT_EQ(live["node"], "listener");
  // The talker publishes at 50 Hz; the listener's callback takes each one.
  EXPECT_GT(live["messages"].get<int>(), 20) << r.out;
  EXPECT_EQ(live["missed"], 0);
  const double min = live["min_us"], p50 = live["p50_us"], p99 = live["p99_us"],
               max = live["max_us"];
  EXPECT_GT(min, 0.0);
  EXPECT_LE(min, p50);
  EXPECT_LE(p50, p99);
  EXPECT_LE(p99, max);
  EXPECT_LT(p50, 1e6) << "a delay of a second under emulation is no delay but a fault";
  // The stopped listener's callbacks do not run: none timed.
  const json frozen = find_by(window["subscribers"], "pid", stopped);
  ASSERT_FALSE(frozen.is_null()) << r.out;
  EXPECT_EQ(frozen["messages"], 0);
  EXPECT_TRUE(frozen["p50_us"].is_null());

  const Outcome table = cli("topic delay " + topic + " --window 1 --count 1");
  ASSERT_EQ(table.code, 0) << table.err;
  EXPECT_EQ(row_starting(table.out, "SUBSCRIBER"),
            (std::vector<std::string>{"SUBSCRIBER", "NODE", "MIN_US", "P50_US", "P99_US", "MAX_US",
                                      "MESSAGES"}));
  EXPECT_EQ(lines_of(table.out).size(), 3u) << table.out;
  const Outcome missing = cli("topic delay /nope --count 1");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("no publisher or subscriber uses topic '/nope'"), std::string::npos)
      << missing.err;
  EXPECT_EQ(cli("topic delay " + topic + " --window 0").code, 2);
}

TEST_F(CliLive, NodeInfoAndProcessListShowTheTalker) {
  const json node = cli("node info talker --json").value();
  EXPECT_EQ(node["pids"], json::array({talker}));
  EXPECT_EQ(node["publishers"][0]["topic"], topic);
  EXPECT_EQ(node["publishers"][0]["type"], "chatter/msg/Message");

  const json processes = cli("process list --json").value()["processes"];
  const json talker_process = find_by(processes, "pid", talker);
  ASSERT_FALSE(talker_process.is_null()) << processes.dump();
  EXPECT_EQ(talker_process["uid"], 0);
  EXPECT_EQ(talker_process["nodes"], json::array({"talker"}));
  const json pool = talker_process["pool"];
  ASSERT_FALSE(pool.is_null()) << processes.dump();
  EXPECT_GT(pool["size"].get<std::uint64_t>(), 0u);
  // The talker has written messages into its pool: some of it is resident.
  EXPECT_GT(pool["used"].get<std::uint64_t>(), 0u);
  EXPECT_LE(pool["used"].get<std::uint64_t>(), pool["size"].get<std::uint64_t>());
  EXPECT_GE(pool["messages"].get<std::uint64_t>(), 1u);
}

TEST_F(CliLive, QueueListShowsOwnersDepthsAndTheStaleGhost) {
  const json info = cli("topic info " + topic + " --json").value();
  const json frozen = find_by(info["subscribers"], "pid", stopped);
  const Outcome r = cli("queue list --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json queues = r.value()["queues"];

  const json frozen_queue = find_by(queues, "name", frozen["queue"]);
  ASSERT_FALSE(frozen_queue.is_null()) << queues.dump();
  EXPECT_EQ(frozen_queue, json({{"name", frozen["queue"]},
                                {"topic", topic},
                                {"subscriber_id", frozen["id"]},
                                {"pid", stopped},
                                {"pending", 1},
                                {"capacity", 10},
                                {"stale", false}}));
  const json live_queue = find_by(queues, "pid", listener);
  ASSERT_FALSE(live_queue.is_null());
  EXPECT_EQ(live_queue["stale"], false);
  EXPECT_EQ(live_queue["capacity"], 10);

  EXPECT_EQ(find_by(queues, "name", "/ghost@7"), json({{"name", "/ghost@7"},
                                                       {"topic", nullptr},
                                                       {"subscriber_id", 7},
                                                       {"pid", nullptr},
                                                       {"pending", 0},
                                                       {"capacity", 10},
                                                       {"stale", true}}));

  const Outcome table = cli("queue list");
  ASSERT_EQ(table.code, 0);
  EXPECT_EQ(row_starting(table.out, "/ghost@7"),
            (std::vector<std::string>{"/ghost@7", "-", "7", "-", "0", "10", "yes"}));
  EXPECT_EQ(row_starting(table.out, frozen["queue"]),
            (std::vector<std::string>{frozen["queue"], topic, frozen["id"].dump(),
                                      std::to_string(stopped), "1", "10", "no"}));
  expect_ends_under_header(table.out, "CAPACITY", line_containing(table.out, "/ghost@7"));
}

TEST_F(CliLive, NodeListGroupsByProcess) {
  const Outcome r = cli("node list --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json nodes = r.value()["nodes"];
  EXPECT_EQ(find_by(nodes, "pid", talker), json({{"name", "talker"},
                                                 {"pid", talker},
                                                 {"publishes", {topic}},
                                                 {"subscribes", json::array()},
                                                 {"serves", json::array()},
                                                 {"calls", json::array()}}));
  EXPECT_EQ(find_by(nodes, "pid", stopped), json({{"name", "stopped"},
                                                  {"pid", stopped},
                                                  {"publishes", json::array()},
                                                  {"subscribes", {topic}},
                                                  {"serves", json::array()},
                                                  {"calls", json::array()}}));

  const Outcome table = cli("node list");
  ASSERT_EQ(table.code, 0);
  EXPECT_EQ(row_starting(table.out, "talker"),
            (std::vector<std::string>{"talker", std::to_string(talker), topic, "-", "-", "-"}));
  EXPECT_EQ(row_starting(table.out, "listener"),
            (std::vector<std::string>{"listener", std::to_string(listener), "-", topic, "-", "-"}));
}

TEST_F(CliLive, AnUnprivilegedUserInspectsWhatItMayOpen) {
  ::chmod(".", 0777);  // that user writes its output files here
  constexpr uid_t nobody = 65534;
  // The module creates the device 0660 root:root; the udev rule (or
  // agnocastd's device.group) gives it to group agnocast.
  ASSERT_EQ(::chown("/dev/agnocast", 0, vm_agnocast_gid), 0);
  const Outcome outsider = cli("topic list --json", nobody);
  EXPECT_EQ(outsider.code, 1);
  EXPECT_NE(outsider.err.find("group agnocast"), std::string::npos) << outsider.err;
  const std::vector<gid_t> member{vm_agnocast_gid};
  const Outcome policy = cli("policy show --json", nobody, member);
  ASSERT_EQ(policy.code, 0) << policy.err;
  EXPECT_EQ(policy.value(), json::parse(R"({"policy": null})"));
  const Outcome list = cli("topic list --json", nobody, member);
  ASSERT_EQ(list.code, 0) << list.err;
  EXPECT_FALSE(find_by(list.value()["topics"], "name", topic).is_null());
  EXPECT_EQ(cli("topic info " + topic + " --json", nobody, member).code, 0);
  // The ghost queue is root's, mode 0600: shown, its depth unknown to this user.
  const Outcome queues = cli("queue list --json", nobody, member);
  ASSERT_EQ(queues.code, 0) << queues.err;
  const json ghost = find_by(queues.value()["queues"], "name", "/ghost@7");
  EXPECT_TRUE(ghost["pending"].is_null()) << ghost.dump();
  EXPECT_TRUE(ghost["capacity"].is_null());
  EXPECT_EQ(ghost["stale"], true);
  EXPECT_TRUE(cli("version --json", nobody, member).value()["module"].is_string());
  // Outside the group, the module version still comes from sysfs.
  EXPECT_TRUE(cli("version --json", nobody).value()["module"].is_string());
}

TEST_F(CliLive, VersionReportsTheLoadedModule) {
  const Outcome r = cli("version --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json v = r.value();
  EXPECT_TRUE(v["module"].is_string());
  EXPECT_EQ(v["module"], v["library"]);
  EXPECT_EQ(row_starting(cli("version").out, "module"),
            (std::vector<std::string>{"module", v["module"]}));
}

TEST_F(CliLive, DoctorWithoutDaemonFailsOnlyTheDaemonCheck) {
  const Outcome r = cli("doctor --json");
  EXPECT_EQ(r.code, 1);
  const json checks = r.value()["checks"];
  ASSERT_FALSE(checks.empty());
  for (const json& check : checks) {
    EXPECT_EQ(check["ok"], check["name"] != "daemon") << check.dump();
  }
  const Outcome table = cli("doctor");
  EXPECT_EQ(table.code, 1);
  EXPECT_EQ(row_starting(table.out, "daemon").at(1), "FAIL");
  EXPECT_EQ(row_starting(table.out, "module").at(1), "ok");
}

TEST_F(CliLive, DaemonStatusStoppedThenRunning) {
  Outcome r = cli("daemon status --json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.value()["running"], false);
  EXPECT_EQ(r.value()["module_loaded"], true);
  EXPECT_NE(r.err.find("systemctl start agnocastd"), std::string::npos);

  // agnocastd sweeps stale queues: the ghost test above has already run.
  pid_t daemon = spawn({"agnocastd", "--no-load"}, "agnocastd.log");
  ASSERT_TRUE(eventually(
      [&] {
        r = cli("daemon status --json");
        return r.code == 0 && r.value()["running"] == true;
      },
      patience))
      << r.out << slurp("agnocastd.log");
  const json status = r.value();
  EXPECT_EQ(status["pid"], daemon);
  EXPECT_EQ(status["module_loaded"], true);
  EXPECT_EQ(status["module_version"], cli("version --json").value()["module"]);
  EXPECT_GE(status["uptime_s"].get<int>(), 0);
  json agnocastd = status;  // agnocastd's own fields, beside the other daemons'
  agnocastd.erase("bridge");
  agnocastd.erase("foxglove");
  EXPECT_EQ(agnocastd.size(), 8u);
  EXPECT_EQ(status["bridge"]["running"], false);
  EXPECT_EQ(status["foxglove"]["running"], false);
  EXPECT_EQ(cli("doctor").code, 0) << cli("doctor").out;
  EXPECT_EQ(row_starting(cli("daemon status").out, "running"),
            (std::vector<std::string>{"running", "yes"}));
  ::kill(daemon, SIGTERM);
  ::waitpid(daemon, nullptr, 0);
  EXPECT_EQ(cli("daemon status --json").value()["running"], false);
}

TEST_F(CliLive, ExitCodes) {
  EXPECT_EQ(cli("topic list").code, 0);
  const Outcome usage = cli("topic info");
  EXPECT_EQ(usage.code, 2);
  EXPECT_EQ(usage.out, "");
  EXPECT_EQ(cli("frobnicate").code, 2);
  EXPECT_EQ(cli("topic info bad-name").code, 2);
  const Outcome json_usage = cli("--json queue");
  EXPECT_EQ(json_usage.code, 2);
  EXPECT_EQ(json_usage.value()["exit_code"], 2);
  const Outcome missing = cli("topic info /nope");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("topic list"), std::string::npos);
  const Outcome json_missing = cli("topic info /nope --json");
  EXPECT_EQ(json_missing.code, 1);
  EXPECT_EQ(json_missing.value()["exit_code"], 1);
  // No service runs here: an empty list, and none to show.
  EXPECT_EQ(cli("service list --json").value(), json::parse(R"({"services":[]})"));
  EXPECT_EQ(cli("service info /nope").code, 1);
  EXPECT_EQ(cli("service type bad-name").code, 2);
}

// After every test that looks at the stopped listener: resumed, its one
// notification wakes it and it receives every entry the kernel kept for it.
TEST_F(CliLive, TheStoppedListenerResumesAndReceivesEveryKeptEntry) {
  ASSERT_EQ(::kill(talker, SIGSTOP), 0);  // nothing new meanwhile
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const json before = subscriber_of(stopped);
  ASSERT_FALSE(before.is_null());
  EXPECT_EQ(before["received"], 0);
  EXPECT_EQ(before["unreceived"], 10);
  EXPECT_EQ(queued_notifications(before["queue"].get<std::string>()), 1);

  ASSERT_EQ(::kill(stopped, SIGCONT), 0);
  json after;
  EXPECT_TRUE(eventually(
      [&] {
        after = subscriber_of(stopped);
        return !after.is_null() && after["received"] == 10 && after["unreceived"] == 0 &&
               queued_notifications(after["queue"].get<std::string>()) == 0;
      },
      patience))
      << after.dump();
  EXPECT_EQ(after["pending"], 0);
  EXPECT_EQ(after["dropped"], before["dropped"]) << "nothing dropped once it resumed";
  ASSERT_EQ(::kill(talker, SIGCONT), 0);
}

// Last: it removes the module (and puts it back).
TEST_F(CliLive, WithoutTheModuleDoctorFailsAndCommandsSayHowToFix) {
  TearDownTestSuite();
  ASSERT_EQ(std::system("rmmod agnocast"), 0) << "cannot remove agnocast.ko";

  const Outcome doctor = cli("doctor --json");
  EXPECT_EQ(doctor.code, 1);
  const json checks = doctor.value()["checks"];
  ASSERT_FALSE(checks.empty());
  for (const json& check : checks) {
    if (check["name"] == "module" || check["name"] == "device" || check["name"] == "version") {
      EXPECT_EQ(check["ok"], false) << check.dump();
    }
  }
  const Outcome list = cli("topic list");
  EXPECT_EQ(list.code, 1);
  EXPECT_EQ(list.out, "");
  EXPECT_NE(list.err.find("systemctl start agnocastd"), std::string::npos) << list.err;
  const Outcome version = cli("version --json");
  EXPECT_EQ(version.code, 0);
  EXPECT_TRUE(version.value()["module"].is_null());
  // Every leftover queue is stale without the module.
  const json queues = cli("queue list --json").value()["queues"];
  for (const json& q : queues) {
    EXPECT_EQ(q["stale"], true) << q.dump();
  }

  const char* module = std::getenv("AGNOCAST_MODULE");
  ASSERT_NE(module, nullptr);
  EXPECT_EQ(std::system(("insmod " + std::string(module)).c_str()), 0);
  EXPECT_EQ(cli("topic list").code, 0);
}

}  // namespace
