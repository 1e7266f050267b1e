// The trace's pure parts: the two text parsers, the Chrome JSON they become,
// and the report read back from it; and trace's bad input through run_cli.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "cli.hpp"
#include "fake_source.hpp"
#include "trace/chrome_trace.hpp"
#include "trace/trace_event.hpp"
#include "trace/trace_report.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

// One babeltrace2 line of the agnocast provider, as `trace record` reads it.
std::string lttng_line(std::int64_t ns, int pid, int tid, const std::string& process,
                       const std::string& event, const std::string& fields) {
  return "[" + std::to_string(ns) + "] host agnocast:" + event +
         ": { cpu_id = 0 }, { vpid = " + std::to_string(pid) + ", vtid = " + std::to_string(tid) +
         ", procname = \"" + process + "\" }, { " + fields + " }\n";
}

// A talker (pid 100) whose 1 ms timer publishes /a entries 1 and 2; a relay
// (pid 200, thread 201) republishing each on /b as entries 11 and 12; a
// listener (pid 300) on /b. Times in µs, as the trace writes them.
std::string pipeline_text() {
  std::string text;
  auto add = [&](double us, int pid, int tid, const char* process, const char* event,
                 const std::string& fields) {
    text += lttng_line(static_cast<std::int64_t>(us * 1000), pid, tid, process, event, fields);
  };
  add(1, 100, 100, "talker", "agnocast_node_init", "node_handle = 0x10, node_name = \"talker\"");
  add(2, 100, 100, "talker", "agnocast_publisher_init",
      "publisher_handle = 0x20, node_handle = 0x10, topic_name = \"/a\", queue_depth = 10, "
      "publisher_id = 1");
  add(3, 100, 100, "talker", "agnocast_timer_init",
      "timer_handle = 0x30, node_handle = 0x10, callback = 0x30, callback_group = 0x0, "
      "period = 1000000");
  add(4, 200, 200, "relay", "agnocast_node_init", "node_handle = 0x10, node_name = \"relay\"");
  add(5, 200, 200, "relay", "agnocast_subscription_init",
      "subscription_handle = 0x40, node_handle = 0x10, callback = 0x40, callback_group = 0x0, "
      "symbol = \"raw\", topic_name = \"/a\", queue_depth = 10, pid_ciid = 1, subscriber_id = 2");
  add(6, 200, 200, "relay", "agnocast_publisher_init",
      "publisher_handle = 0x50, node_handle = 0x10, topic_name = \"/b\", queue_depth = 10, "
      "publisher_id = 1");
  add(7, 300, 300, "listener", "agnocast_node_init",
      "node_handle = 0x10, node_name = \"listener\"");
  add(8, 300, 300, "listener", "agnocast_subscription_init",
      "subscription_handle = 0x60, node_handle = 0x10, callback = 0x60, callback_group = 0x0, "
      "symbol = \"raw\", topic_name = \"/b\", queue_depth = 10, pid_ciid = 2, subscriber_id = 2");
  for (int k = 0; k < 2; ++k) {
    const double t = 1000.0 * (k + 1);
    const std::string a = std::to_string(k + 1), b = std::to_string(k + 11);
    add(t, 100, 100, "talker", "agnocast_callable_start", "callable = 0x30");
    add(t + 1, 100, 100, "talker", "agnocast_publish",
        "publisher_handle = 0x20, entry_id = " + a + ", topic_name = \"/a\", publisher_id = 1");
    add(t + 2, 100, 100, "talker", "agnocast_callable_end", "callable = 0x30");
    // The relay takes 10 µs (first) and 30 µs (second) to start.
    const double r = t + 1 + 10 + 20 * k;
    add(r - 1, 200, 201, "relay", "agnocast_take",
        "subscription_handle = 0x40, message = 0x7000, entry_id = " + a +
            ", topic_name = \"/a\", subscriber_id = 2");
    add(r - 0.5, 200, 201, "relay", "agnocast_create_callable",
        "callable = 0x40, entry_id = " + a + ", pid_ciid = 1");
    add(r, 200, 201, "relay", "agnocast_callable_start", "callable = 0x40");
    add(r + 4, 200, 201, "relay", "agnocast_publish",
        "publisher_handle = 0x50, entry_id = " + b + ", topic_name = \"/b\", publisher_id = 1");
    add(r + 5, 200, 201, "relay", "agnocast_callable_end", "callable = 0x40");
    // The listener starts 100 µs after the relay's publish.
    add(r + 104, 300, 300, "listener", "agnocast_take",
        "subscription_handle = 0x60, message = 0x8000, entry_id = " + b +
            ", topic_name = \"/b\", subscriber_id = 2");
    add(r + 104.5, 300, 300, "listener", "agnocast_callable_start", "callable = 0x60");
    add(r + 110, 300, 300, "listener", "agnocast_callable_end", "callable = 0x60");
  }
  return text;
}

json events_of(const json& trace, const std::string& phase, const std::string& cat = "") {
  json found = json::array();
  for (const json& event : trace["traceEvents"]) {
    if (event["ph"] == phase && (cat.empty() || event.value("cat", "") == cat)) {
      found.push_back(event);
    }
  }
  return found;
}

TEST(TraceEvent, BabeltraceLinesGiveTimeThreadProcessAndFields) {
  const auto events = parse_lttng_text(
      "[00000045541842039004] vm agnocast:agnocast_take: { cpu_id = 0 }, { vpid = 31352, vtid = "
      "31360, procname = \"agnocast_trace_\" }, { subscription_handle = 0x55FEB0ED9DC0, message "
      "= 0x7FA182D3C060, entry_id = 1 }\n"
      "[5] vm agnocast:agnocast_node_init: { cpu_id = 1 }, { vpid = 7, vtid = 7, procname = "
      "\"a, b\" }, { node_handle = 0x1, node_name = \"say \\\"hi\\\", then go\" }\n"
      "not an event\n"
      "[6] vm agnocast:agnocast_publish: { cpu_id = 0 }, { publisher_handle = 0x1, entry_id = 2 "
      "}\n");
  ASSERT_EQ(events.size(), 2u);  // the last has no vpid/vtid: no track for it
  EXPECT_EQ(events[0].time_ns, 45541842039004);
  EXPECT_EQ(events[0].pid, 31352);
  EXPECT_EQ(events[0].tid, 31360);
  EXPECT_EQ(events[0].process, "agnocast_trace_");
  EXPECT_EQ(events[0].name, "agnocast_take");
  EXPECT_EQ(events[0].number("subscription_handle"), 0x55FEB0ED9DC0);
  EXPECT_EQ(events[0].number("entry_id"), 1);
  EXPECT_EQ(events[0].number("missing"), std::nullopt);
  EXPECT_EQ(events[1].process, "a, b");
  EXPECT_EQ(events[1].text("node_name"), "say \"hi\", then go");
}

TEST(TraceEvent, TracefsLinesOfTheModuleOnly) {
  const auto events = parse_tracefs_text(
      "# tracer: nop\n"
      "#\n"
      "     my-talker-2-412     [001] .....   123.456789: publish: topic=/chatter topic_id=1 "
      "entry_id=5 publisher_id=1 pid=412 bytes=64 woken=1\n"
      "          <idle>-0       [000] d..2.   123.500000: sched_switch: prev_comm=x\n"
      "        listener-500     [000] .....   124.000001: receive: topic=/chatter topic_id=1 "
      "subscriber_id=2 pid=499 entry_id=5 publisher_id=1 entries=1\n");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].name, "publish");
  EXPECT_EQ(events[0].time_ns, 123'456'789'000);
  EXPECT_EQ(events[0].process, "my-talker-2");
  EXPECT_EQ(events[0].tid, 412);
  EXPECT_EQ(events[0].pid, 412);
  EXPECT_EQ(events[0].text("topic"), "/chatter");
  EXPECT_EQ(events[0].number("woken"), 1);
  EXPECT_EQ(events[1].name, "receive");
  EXPECT_EQ(events[1].pid, 499);  // the field, not the task
  EXPECT_EQ(events[1].tid, 500);
}

TEST(ChromeTrace, SlicesPerCallbackAndAFlowFromEachPublishToItsCallback) {
  RecordedTrace recorded;
  recorded.library = parse_lttng_text(pipeline_text());
  recorded.counts.push_back({1'000'000, "/a", 1, 2});
  const json trace = chrome_trace(recorded);
  EXPECT_EQ(trace["otherData"]["agnocast_trace"], chrome_trace_format);
  EXPECT_EQ(trace["otherData"]["flows"], 4);      // /a twice, /b twice
  EXPECT_EQ(trace["otherData"]["callbacks"], 6);  // timer, relay, listener, twice each
  const json starts = events_of(trace, "s"), finishes = events_of(trace, "f");
  ASSERT_EQ(starts.size(), 4u);
  ASSERT_EQ(finishes.size(), 4u);
  // The first flow: the talker's publish of /a 1 at 1001 µs to the relay's
  // callback start at 1011 µs on its thread 201.
  EXPECT_EQ(starts[0]["name"], "/a");
  EXPECT_EQ(starts[0]["pid"], 100);
  EXPECT_DOUBLE_EQ(starts[0]["ts"].get<double>(), 1001);
  EXPECT_EQ(finishes[0]["id"], starts[0]["id"]);
  EXPECT_EQ(finishes[0]["bp"], "e");
  EXPECT_EQ(finishes[0]["pid"], 200);
  EXPECT_EQ(finishes[0]["tid"], 201);
  EXPECT_DOUBLE_EQ(finishes[0]["ts"].get<double>(), 1011);
  const json callbacks = events_of(trace, "X", "callback");
  ASSERT_EQ(callbacks.size(), 6u);
  EXPECT_EQ(callbacks[0]["name"], "timer 1 ms");
  EXPECT_EQ(callbacks[1]["name"], "callback /a");
  EXPECT_EQ(callbacks[1]["args"]["node"], "relay");
  EXPECT_EQ(callbacks[1]["args"]["entry_id"], 1);
  EXPECT_DOUBLE_EQ(callbacks[1]["dur"].get<double>(), 5);
  const json counters = events_of(trace, "C");
  ASSERT_EQ(counters.size(), 1u);
  EXPECT_EQ(counters[0]["args"]["unreceived"], 2);
  std::set<std::string> names;
  for (const json& meta : events_of(trace, "M")) {
    if (meta["name"] == "process_name") names.insert(meta["args"]["name"].get<std::string>());
  }
  EXPECT_EQ(names, (std::set<std::string>{"talker", "relay", "listener", "agnocast entries"}));
}

TEST(ChromeTrace, ProcessesStartedBeforeTheRecordingAreFollowedByTopicAndNamedByTheKernel) {
  // No init events: the session began after the endpoints were made.
  std::string text;
  std::istringstream lines(pipeline_text());
  for (std::string line; std::getline(lines, line);) {
    if (line.find("_init:") == std::string::npos) text += line + "\n";
  }
  RecordedTrace recorded;
  recorded.library = parse_lttng_text(text);
  recorded.subscriber_nodes[{"/a", 2}] = "relay";
  recorded.subscriber_nodes[{"/b", 2}] = "listener";
  recorded.publisher_nodes[{"/a", 1}] = "talker";
  const json trace = chrome_trace(recorded);
  EXPECT_EQ(trace["otherData"]["flows"], 4);
  const json callbacks = events_of(trace, "X", "callback");
  ASSERT_EQ(callbacks.size(), 6u);
  EXPECT_EQ(callbacks[0]["name"], "callback");  // the timer: nothing names it
  EXPECT_EQ(callbacks[0]["args"]["callable"], "0x30");
  EXPECT_EQ(callbacks[1]["name"], "callback /a");
  EXPECT_EQ(callbacks[1]["args"]["node"], "relay");
  EXPECT_EQ(callbacks[2]["args"]["node"], "listener");
  const json publishes = events_of(trace, "X", "publish");
  ASSERT_EQ(publishes.size(), 4u);
  EXPECT_EQ(publishes[0]["args"]["node"], "talker");
  EXPECT_EQ(publishes[1]["args"]["node"], "");  // /b's publisher is not in the kernel's map
}

TEST(ChromeTrace, TopicsFilterLeavesOtherTopicsOut) {
  RecordedTrace recorded;
  recorded.library = parse_lttng_text(pipeline_text());
  recorded.topics.emplace("^/b$");
  const json trace = chrome_trace(recorded);
  EXPECT_EQ(trace["otherData"]["flows"], 2);
  for (const json& event : events_of(trace, "s")) EXPECT_EQ(event["name"], "/b");
}

TEST(TraceReport, LatencyPerTopicCallbackDurationsAndThePathThroughTheRelay) {
  RecordedTrace recorded;
  recorded.library = parse_lttng_text(pipeline_text());
  const json report = trace_report_json(chrome_trace(recorded), {"/a", "/b"});
  ASSERT_EQ(report["topics"].size(), 2u);
  const json& a = report["topics"][0];
  EXPECT_EQ(a["topic"], "/a");
  EXPECT_EQ(a["node"], "relay");
  EXPECT_EQ(a["count"], 2);
  EXPECT_DOUBLE_EQ(a["min_us"].get<double>(), 10);
  EXPECT_DOUBLE_EQ(a["max_us"].get<double>(), 30);
  EXPECT_DOUBLE_EQ(a["p50_us"].get<double>(), 10);  // nearest rank of two
  const json& b = report["topics"][1];
  EXPECT_DOUBLE_EQ(b["p50_us"].get<double>(), 100.5);
  // The path: publish of /a to the listener's start: 10 + 4 + 100.5, then 30 + ...
  const json& path = report["path"];
  EXPECT_EQ(path["count"], 2);
  EXPECT_EQ(path["published"], 2);
  EXPECT_EQ(path["incomplete"], 0);
  EXPECT_DOUBLE_EQ(path["min_us"].get<double>(), 114.5);
  EXPECT_DOUBLE_EQ(path["max_us"].get<double>(), 134.5);
  ASSERT_EQ(report["callbacks"].size(), 3u);
  const std::string table = trace_report_table(report);
  EXPECT_NE(table.find("/a -> /b"), std::string::npos);
  EXPECT_NE(table.find("callback /a"), std::string::npos);
}

TEST(TraceReport, APathNoMessageFollowsIsCountedIncomplete) {
  RecordedTrace recorded;
  recorded.library = parse_lttng_text(pipeline_text());
  const json report = trace_report_json(chrome_trace(recorded), {"/b", "/a"});
  EXPECT_EQ(report["path"]["count"], 0);
  EXPECT_EQ(report["path"]["published"], 2);
  EXPECT_EQ(report["path"]["incomplete"], 2);
  EXPECT_TRUE(report["path"]["p50_us"].is_null());
}

TEST(TraceReport, RefusesWhatIsNotATraceRecordWrote) {
  EXPECT_THROW(trace_report_json(json::array(), {}), InputError);
  EXPECT_THROW(trace_report_json(json{{"traceEvents", json::array()}}, {}), InputError);
  EXPECT_THROW(
      trace_report_json(
          json{{"traceEvents", json::array()}, {"otherData", {{"agnocast_trace", "1"}}}}, {}),
      InputError);
  EXPECT_THROW(
      trace_report_json(json{{"traceEvents", {1, 2}}, {"otherData", {{"agnocast_trace", 1}}}}, {}),
      InputError);
  const json foreign = {{"traceEvents", {{{"ph", "f"}, {"cat", "flow"}, {"id", 7}}}},
                        {"otherData", {{"agnocast_trace", 1}}}};
  EXPECT_NO_THROW(trace_report_json(foreign, {}));  // a finish without its start is skipped
  const json broken = {{"traceEvents", {{{"ph", "X"}, {"cat", "callback"}}}},
                       {"otherData", {{"agnocast_trace", 1}}}};
  EXPECT_THROW(trace_report_json(broken, {}), InputError);
}

struct Outcome {
  int code;
  std::string out;
  std::string err;
};

Outcome run(std::vector<const char*> args) {
  FakeSource source = healthy_system();
  args.insert(args.begin(), "agnocast-cli");
  std::ostringstream out, err;
  const int code = run_cli(static_cast<int>(args.size()), args.data(), source, out, err);
  return {code, out.str(), err.str()};
}

TEST(TraceCli, BadInputIsAUsageErrorThatSaysWhy) {
  const std::string file = ::testing::TempDir() + "/not-a-trace.json";
  std::ofstream(file) << "{\"traceEvents\": []}";
  const std::string garbage = ::testing::TempDir() + "/garbage.json";
  std::ofstream(garbage) << "\x89PNG";
  const struct {
    std::vector<const char*> args;
    const char* says;
  } cases[] = {
      {{"trace", "report", "/nonexistent/trace.json"}, "cannot read"},
      {{"trace", "report", file.c_str()}, "not a trace"},
      {{"trace", "report", garbage.c_str()}, "not JSON"},
      {{"trace", "report", file.c_str(), "--path", "/a"}, "two topics"},
      {{"trace", "report", file.c_str(), "--path", "/a,bad name"}, "--path"},
      {{"trace", "record", "--topics", "("}, "not a regular expression"},
      {{"trace", "record", "--topics", "^/nothing$"}, "no topic matches"},
      {{"trace", "record", "--duration", "-1"}, "--duration"},
      {{"trace", "record", "--frobnicate"}, "frobnicate"},
      {{"trace"}, "record"},
  };
  for (const auto& c : cases) {
    const Outcome outcome = run(c.args);
    EXPECT_EQ(outcome.code, exit_usage_error) << c.args.back();
    EXPECT_NE(outcome.err.find(c.says), std::string::npos) << c.args.back() << ": " << outcome.err;
  }
  std::remove(file.c_str());
  std::remove(garbage.c_str());
}

TEST(TraceCli, ReportOfATraceAsTableAndJson) {
  RecordedTrace recorded;
  recorded.library = parse_lttng_text(pipeline_text());
  const std::string file = ::testing::TempDir() + "/pipeline-trace.json";
  std::ofstream(file) << chrome_trace(recorded).dump();
  const Outcome table = run({"trace", "report", file.c_str(), "--path", "/a,/b"});
  EXPECT_EQ(table.code, exit_success) << table.err;
  EXPECT_NE(table.out.find("publish -> callback start"), std::string::npos);
  const Outcome as_json = run({"trace", "report", file.c_str(), "--json"});
  EXPECT_EQ(as_json.code, exit_success);
  EXPECT_EQ(json::parse(as_json.out)["topics"].size(), 2u);
  std::remove(file.c_str());
}

}  // namespace
}  // namespace agnocast::cli
