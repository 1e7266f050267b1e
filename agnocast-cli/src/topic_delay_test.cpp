// topic delay against a fake system whose listener's record grows with the
// fake clock: golden output of whole runs.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>

#include "commands.hpp"
#include "fake_source.hpp"

namespace agnocast::cli {
namespace {

// The listener of healthy_system() (pid 200, subscriber 1) records
// `per_tenth` delays every tenth of a second of the fake clock: the k-th it
// ever records is delay_of(k) ns. Its record keeps the newest 1,024.
FakeSource recording(std::size_t per_tenth, std::function<std::int64_t(std::uint64_t)> delay_of,
                     std::uint64_t recorded_before = 0) {
  FakeSource source = healthy_system();
  source.delays[{200, "/chatter", 1}].count = recorded_before;
  const double start = source.clock;
  source.on_sleep = [=](FakeSource& s) {
    RecordedDelays& r = s.delays[{200, "/chatter", 1}];
    const auto tenths = static_cast<std::uint64_t>(std::llround((s.clock - start) * 10));
    while (r.count < recorded_before + tenths * per_tenth) {
      r.newest_ns.push_back(delay_of(r.count++));
      if (r.newest_ns.size() > 1024) r.newest_ns.erase(r.newest_ns.begin());
    }
  };
  return source;
}

DelayOptions delay(const std::string& topic, double window_s, std::optional<std::size_t> count,
                   bool json = false) {
  DelayOptions options;
  options.topic = topic;
  options.window_s = window_s;
  options.count = count;
  options.json = json;
  return options;
}

std::string run_delay(FakeSource& source, DelayOptions options) {
  std::ostringstream out;
  EXPECT_EQ(topic_delay(source, options, out), exit_success);
  return out.str();
}

TEST(TopicDelay, OneRowPerSubscriberAndWindowWithNearestRankPercentiles) {
  // Ten samples a window, ten delays each: 1 to 100 µs in the first window,
  // 101 to 200 µs in the second. What was recorded before the run is not in it.
  FakeSource source = recording(
      10, [](std::uint64_t k) { return static_cast<std::int64_t>(k - 499) * 1000; }, 500);
  EXPECT_EQ(
      run_delay(source, delay("/chatter", 1.0, 2)),
      "SUBSCRIBER NODE                     MIN_US     P50_US     P99_US     MAX_US  MESSAGES\n"
      "         1 listener                    1.0       50.0       99.0      100.0       100\n"
      "         2 poller                        -          -          -          -         -\n"
      "         1 listener                  101.0      150.0      199.0      200.0       100\n"
      "         2 poller                        -          -          -          -         -\n");
}

TEST(TopicDelay, JsonLinesOneObjectPerWindow) {
  FakeSource source = recording(1, [](std::uint64_t) { return 2500; });
  const std::string out = run_delay(source, delay("/chatter", 0.5, 1, true));
  EXPECT_EQ(
      out,
      R"({"name":"/chatter","subscribers":[{"max_us":2.5,"messages":5,"min_us":2.5,"missed":0,)"
      R"("node":"listener","p50_us":2.5,"p99_us":2.5,"pid":200,"subscriber":1},)"
      R"({"max_us":null,"messages":null,"min_us":null,"missed":null,"node":"poller",)"
      R"("p50_us":null,"p99_us":null,"pid":300,"subscriber":2}],"window_s":0.5})"
      "\n");
}

TEST(TopicDelay, MoreThanTheRecordKeepsBetweenSamplesAreCountedAsMissed) {
  // 1,500 a sample: the record keeps the newest 1,024 of them.
  FakeSource source =
      recording(1500, [](std::uint64_t k) { return static_cast<std::int64_t>(k) * 1000; });
  const auto window = nlohmann::json::parse(run_delay(source, delay("/chatter", 0.1, 1, true)));
  const auto& row = window["subscribers"][0];
  EXPECT_EQ(row["messages"], 1500);
  EXPECT_EQ(row["missed"], 1500 - 1024);
  EXPECT_EQ(row["min_us"], 476.0);  // the oldest kept: delay_of(476)
  EXPECT_EQ(row["max_us"], 1499.0);
}

TEST(TopicDelay, ARecordThatStartsOverCountsFromZero) {
  // After the first sample, subscriber 1 is gone and a new subscriber 1 of
  // the same process records 7 µs every tenth of a second, from zero again.
  FakeSource source = recording(
      0, [](std::uint64_t) { return 0; }, 900);
  const double start = source.clock;
  source.on_sleep = [start](FakeSource& s) {
    RecordedDelays& r = s.delays[{200, "/chatter", 1}];
    const auto tenths = static_cast<std::uint64_t>(std::llround((s.clock - start) * 10));
    if (r.count >= 900) r = RecordedDelays{};
    while (r.count < tenths) {
      r.newest_ns.push_back(7000);
      ++r.count;
    }
  };
  const auto window = nlohmann::json::parse(run_delay(source, delay("/chatter", 0.3, 1, true)));
  EXPECT_EQ(window["subscribers"][0]["messages"], 3);
  EXPECT_EQ(window["subscribers"][0]["p50_us"], 7.0);
}

TEST(TopicDelay, RunsUntilAStopSignalWithoutCount) {
  FakeSource source = recording(1, [](std::uint64_t) { return 1000; });
  const double start = source.clock;
  auto record = source.on_sleep;
  source.on_sleep = [start, record](FakeSource& s) {
    record(s);
    if (s.clock - start > 2.5) s.stop = true;
  };
  const std::string out = run_delay(source, delay("/chatter", 1.0, std::nullopt));
  // The header and two whole windows of two rows each.
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 5);
}

TEST(TopicDelay, AnUnknownTopicIsAnError) {
  FakeSource source = healthy_system();
  std::ostringstream out;
  EXPECT_THROW(topic_delay(source, delay("/nope", 1.0, 1), out), CliError);
}

}  // namespace
}  // namespace agnocast::cli
