// agnocast-cli topic delay TOPIC [--window SEC] [--count N]: for each callback
// subscriber of the topic, the delay from publish() to the start of its
// callback over each window: min, p50, p99, max and how many. The publisher's
// library stamps each message's publish time and each subscriber's library
// keeps its newest delays where this command can read them; no tracing
// session is needed. A subscriber is sampled ten times a second: one that
// takes more than 1,024 messages between two samples has some counted but
// not timed (`missed`).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include "commands.hpp"
#include "topic_windows.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

constexpr double delay_sample_interval_s = 0.1;

// The nearest-rank percentile of sorted values.
std::int64_t percentile(const std::vector<std::int64_t>& sorted, double fraction) {
  const auto rank =
      static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(sorted.size())));
  return sorted[std::max<std::size_t>(rank, 1) - 1];
}

// One subscriber's window so far.
struct Window {
  std::uint64_t last_count = 0;  // its record's count when last sampled
  std::uint64_t messages = 0;
  std::uint64_t missed = 0;  // counted, but overwritten before a sample saw them
  std::vector<std::int64_t> delays_ns;
};

class DelayMeter {
 public:
  DelayMeter(InspectionSource& source, std::string topic)
      : source_(source), topic_(std::move(topic)), sampled_at_(source_.now_seconds()) {
    sample(true);
  }

  // Samples until `window_s` passed; nullopt when a stop signal cut it short.
  std::optional<json> measure(double window_s) {
    const double start = sampled_at_;
    const double end = start + window_s;
    for (auto& [key, window] : windows_) {
      window = Window{window.last_count, 0, 0, {}};
    }
    while (sampled_at_ < end) {
      if (source_.stop_requested()) return std::nullopt;
      source_.sleep_seconds(std::min(delay_sample_interval_s, end - sampled_at_));
      sample(false);
      sampled_at_ = source_.now_seconds();
    }
    json subscribers = json::array();
    for (const SubscriberInfo& subscriber : subscribers_) {
      const auto found = windows_.find(subscriber.id);
      json row = {{"subscriber", subscriber.id}, {"node", subscriber.node}, {"pid", subscriber.pid},
                  {"min_us", nullptr},           {"p50_us", nullptr},       {"p99_us", nullptr},
                  {"max_us", nullptr},           {"messages", nullptr},     {"missed", nullptr}};
      if (found != windows_.end()) {
        Window& window = found->second;
        row["messages"] = window.messages;
        row["missed"] = window.missed;
        std::sort(window.delays_ns.begin(), window.delays_ns.end());
        if (!window.delays_ns.empty()) {
          auto us = [](std::int64_t ns) { return rounded(static_cast<double>(ns) / 1e3, 1e3); };
          row["min_us"] = us(window.delays_ns.front());
          row["p50_us"] = us(percentile(window.delays_ns, 0.5));
          row["p99_us"] = us(percentile(window.delays_ns, 0.99));
          row["max_us"] = us(window.delays_ns.back());
        }
      }
      subscribers.push_back(row);
    }
    return json{{"name", topic_},
                {"window_s", rounded(sampled_at_ - start, 1e3)},
                {"subscribers", subscribers}};
  }

 private:
  // Reads every subscriber's record; the first sample only sets where each
  // window starts counting. A subscriber without a record (a polling one, or
  // a process that keeps none) has no window.
  void sample(bool first) {
    subscribers_ = require_topic(source_, topic_).subscribers;
    std::map<std::uint32_t, Window> next;
    for (const SubscriberInfo& subscriber : subscribers_) {
      const std::optional<RecordedDelays> recorded =
          subscriber.polling ? std::nullopt
                             : source_.recorded_delays(subscriber.pid, topic_, subscriber.id);
      if (!recorded) continue;
      const auto known = windows_.find(subscriber.id);
      Window window = known == windows_.end() ? Window{} : std::move(known->second);
      if (first) window.last_count = recorded->count;
      // A count that went back is a new subscriber of the same id.
      if (recorded->count < window.last_count) window.last_count = 0;
      const std::uint64_t fresh = recorded->count - window.last_count;
      const std::size_t seen = std::min<std::uint64_t>(fresh, recorded->newest_ns.size());
      window.delays_ns.insert(window.delays_ns.end(),
                              recorded->newest_ns.end() - static_cast<std::ptrdiff_t>(seen),
                              recorded->newest_ns.end());
      window.messages += fresh;
      window.missed += fresh - seen;
      window.last_count = recorded->count;
      next.emplace(subscriber.id, std::move(window));
    }
    windows_ = std::move(next);
  }

  InspectionSource& source_;
  std::string topic_;
  std::vector<SubscriberInfo> subscribers_;
  std::map<std::uint32_t, Window> windows_;  // by subscriber id
  double sampled_at_;
};

}  // namespace

std::string topic_delay_header() {
  char line[128];
  std::snprintf(line, sizeof line, "%10s %-20s %10s %10s %10s %10s %9s\n", "SUBSCRIBER", "NODE",
                "MIN_US", "P50_US", "P99_US", "MAX_US", "MESSAGES");
  return line;
}

std::string topic_delay_lines(const json& window) {
  std::string lines;
  for (const json& row : window.at("subscribers")) {
    char line[256];
    std::snprintf(line, sizeof line, "%10u %-20s %10s %10s %10s %10s %9s\n",
                  row.at("subscriber").get<unsigned>(), row.at("node").get<std::string>().c_str(),
                  number_or_dash(row.at("min_us"), "%.1f").c_str(),
                  number_or_dash(row.at("p50_us"), "%.1f").c_str(),
                  number_or_dash(row.at("p99_us"), "%.1f").c_str(),
                  number_or_dash(row.at("max_us"), "%.1f").c_str(),
                  number_or_dash(row.at("messages"), "%.0f").c_str());
    lines += line;
  }
  return lines;
}

int topic_delay(InspectionSource& source, const DelayOptions& options, std::ostream& out) {
  DelayMeter meter(source, options.topic);
  return stream_windows(
      options, out, topic_delay_header(), [&] { return meter.measure(options.window_s); },
      topic_delay_lines);
}

void set_topic_delay_command(CLI::App& topic, Context& context) {
  add_window_command(
      topic, context, "delay",
      "Delay from publish() to the start of each callback subscriber's callback: min, p50, "
      "p99 and max per window, from what the subscribers' processes record; until SIGINT or "
      "--count windows",
      topic_delay);
}

}  // namespace agnocast::cli
