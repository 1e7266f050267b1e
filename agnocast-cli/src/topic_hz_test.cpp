// topic hz against a fake system whose publisher's counters advance with the
// fake clock: golden output of whole runs.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "commands.hpp"
#include "fake_source.hpp"

namespace agnocast::cli {
namespace {

// The talker of healthy_system() publishes 1000-byte messages at the given
// milliseconds (of the fake clock, from the start of the run), in turn.
FakeSource publishing_at(std::vector<int> milliseconds, int repeat_every_ms) {
  FakeSource source = healthy_system();
  const double start = source.clock;
  source.on_sleep = [=, next = std::size_t{0}, base = 0](FakeSource& s) mutable {
    const int now_ms = static_cast<int>(std::lround((s.clock - start) * 1000));
    while (base + milliseconds[next] <= now_ms) {
      s.topics[0].publishers[0].published += 1;
      s.topics[0].publishers[0].published_bytes += 1000;
      if (++next == milliseconds.size()) {
        next = 0;
        base += repeat_every_ms;
      }
    }
  };
  return source;
}

HzOptions hz(const std::string& topic, double window_s, std::optional<std::size_t> count,
             bool json = false) {
  HzOptions options;
  options.topic = topic;
  options.window_s = window_s;
  options.count = count;
  options.json = json;
  return options;
}

std::string run_hz(FakeSource& source, HzOptions options) {
  std::ostringstream out;
  EXPECT_EQ(topic_hz(source, options, out), exit_success);
  return out.str();
}

TEST(TopicHz, OneLinePerWindowWithPeriodJitterAndPayloadBandwidth) {
  // Messages at 40, 100, 140, 200, ... ms: periods alternate 60 and 40 ms.
  // The first window has 19 periods (ten of 60 ms: std dev 9.986 ms); the
  // second's first period reaches back to the first's last message (20
  // periods, ten each: 10 ms).
  FakeSource source = publishing_at({40, 100}, 100);
  EXPECT_EQ(run_hz(source, hz("/chatter", 1.0, 2)),
            "   RATE_HZ      MIN_S      MAX_S  STD_DEV_S    BYTES_PER_S  MESSAGES PUBLISHERS\n"
            "    20.000   0.040000   0.060000   0.009986        20000.0        20          1\n"
            "    20.000   0.040000   0.060000   0.010000        20000.0        20          1\n");
}

TEST(TopicHz, JsonLinesOneObjectPerWindow) {
  // Half-second windows: 9 periods (five of 60 ms), then 10 (five each).
  FakeSource source = publishing_at({40, 100}, 100);
  const std::string out = run_hz(source, hz("/chatter", 0.5, 2, true));
  EXPECT_EQ(out,
            R"({"bytes":10000,"bytes_per_s":20000.0,"max_s":0.06,"messages":10,"min_s":0.04,)"
            R"("name":"/chatter","publishers":1,"rate_hz":20.0,"std_dev_s":0.009938,)"
            R"("window_s":0.5})"
            "\n"
            R"({"bytes":10000,"bytes_per_s":20000.0,"max_s":0.06,"messages":10,"min_s":0.04,)"
            R"("name":"/chatter","publishers":1,"rate_hz":20.0,"std_dev_s":0.01,"window_s":0.5})"
            "\n");
}

TEST(TopicHz, NoPeriodBeforeTwoMessages) {
  FakeSource source = healthy_system();
  EXPECT_EQ(run_hz(source, hz("/chatter", 1.0, 1)),
            "   RATE_HZ      MIN_S      MAX_S  STD_DEV_S    BYTES_PER_S  MESSAGES PUBLISHERS\n"
            "     0.000          -          -          -            0.0         0          1\n");
}

TEST(TopicHz, RunsUntilAStopSignalWithoutCount) {
  FakeSource source = publishing_at({50}, 50);
  const double start = source.clock;
  source.on_sleep = [start](FakeSource& s) {
    if (s.clock - start > 3.5) s.stop = true;
  };
  const std::string out = run_hz(source, hz("/chatter", 1.0, std::nullopt));
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 4);  // header and three whole windows
}

TEST(TopicHz, APublisherJoiningCountsFromZeroAndNoSubscriberIsCreated) {
  FakeSource source = healthy_system();
  source.on_sleep = [](FakeSource& s) {
    if (s.topics[0].publishers.size() == 1) {
      PublisherInfo late;
      late.id = 3;
      late.published = 5;
      late.published_bytes = 500;
      s.topics[0].publishers.push_back(late);
    }
  };
  const std::string out = run_hz(source, hz("/chatter", 1.0, 1, true));
  const auto window = nlohmann::json::parse(out);
  EXPECT_EQ(window["messages"], 5);
  EXPECT_EQ(window["bytes"], 500);
  EXPECT_EQ(window["publishers"], 2);
  EXPECT_EQ(source.topics[0].subscribers.size(), 2u);
}

TEST(TopicHz, AnUnknownTopicIsAnError) {
  FakeSource source = healthy_system();
  std::ostringstream out;
  EXPECT_THROW(topic_hz(source, hz("/nope", 1.0, 1), out), CliError);
}

}  // namespace
}  // namespace agnocast::cli
