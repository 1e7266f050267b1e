// agnocast-cli topic hz TOPIC [--window SEC] [--count N]: publish rate, period
// jitter and payload bandwidth, one line per window, from the kernel's
// per-publisher counters. It never subscribes: the counters are sampled every
// millisecond, and the messages a sample finds are spread evenly over the
// millisecond before it, so periods are exact to about a millisecond.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "commands.hpp"
#include "topic_windows.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

constexpr double hz_sample_interval_s = 0.001;

struct Counters {
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;
};

std::map<std::uint32_t, Counters> sample(InspectionSource& source, const std::string& topic) {
  std::map<std::uint32_t, Counters> by_publisher;
  for (const PublisherInfo& p : require_topic(source, topic).publishers) {
    by_publisher[p.id] = {p.published, p.published_bytes};
  }
  return by_publisher;
}

// What happened between two samples. A publisher that joined counts from
// zero; one that left takes its counts with it.
Counters delta(const std::map<std::uint32_t, Counters>& before,
               const std::map<std::uint32_t, Counters>& after) {
  Counters sum;
  for (const auto& [id, now] : after) {
    const auto then = before.find(id);
    const Counters base = then == before.end() ? Counters{} : then->second;
    sum.messages += now.messages - std::min(now.messages, base.messages);
    sum.bytes += now.bytes - std::min(now.bytes, base.bytes);
  }
  return sum;
}

// The state carried from window to window: the last counters and the last
// message's time, so that the first period of a window starts in the one before.
class HzMeter {
 public:
  HzMeter(InspectionSource& source, std::string topic)
      : source_(source),
        topic_(std::move(topic)),
        counters_(sample(source_, topic_)),
        sampled_at_(source_.now_seconds()) {}

  // Samples until `window_s` passed; nullopt when a stop signal cut it short.
  std::optional<json> measure(double window_s) {
    const double start = sampled_at_;
    const double end = start + window_s;
    Counters total;
    std::vector<double> periods;
    while (sampled_at_ < end) {
      if (source_.stop_requested()) return std::nullopt;
      source_.sleep_seconds(std::min(hz_sample_interval_s, end - sampled_at_));
      const auto now_counters = sample(source_, topic_);
      const double now = source_.now_seconds();
      const Counters got = delta(counters_, now_counters);
      for (std::uint64_t i = 1; i <= got.messages; ++i) {
        const double at = sampled_at_ + (now - sampled_at_) * static_cast<double>(i) / got.messages;
        if (last_message_at_) periods.push_back(at - *last_message_at_);
        last_message_at_ = at;
      }
      total.messages += got.messages;
      total.bytes += got.bytes;
      counters_ = now_counters;
      sampled_at_ = now;
    }
    const double seconds = sampled_at_ - start;
    json value = {{"name", topic_},
                  {"window_s", rounded(seconds, 1e3)},
                  {"publishers", counters_.size()},
                  {"messages", total.messages},
                  {"bytes", total.bytes},
                  {"rate_hz", rounded(static_cast<double>(total.messages) / seconds, 1e3)},
                  {"min_s", nullptr},
                  {"max_s", nullptr},
                  {"std_dev_s", nullptr},
                  {"bytes_per_s", rounded(static_cast<double>(total.bytes) / seconds, 1e3)}};
    if (!periods.empty()) {
      const auto [min, max] = std::minmax_element(periods.begin(), periods.end());
      double mean = 0;
      for (const double p : periods) mean += p;
      mean /= static_cast<double>(periods.size());
      double variance = 0;
      for (const double p : periods) variance += (p - mean) * (p - mean);
      variance /= static_cast<double>(periods.size());
      value["min_s"] = rounded(*min, 1e6);
      value["max_s"] = rounded(*max, 1e6);
      value["std_dev_s"] = rounded(std::sqrt(variance), 1e6);
    }
    return value;
  }

 private:
  InspectionSource& source_;
  std::string topic_;
  std::map<std::uint32_t, Counters> counters_;
  double sampled_at_;
  std::optional<double> last_message_at_;
};

}  // namespace

std::string topic_hz_header() {
  char line[128];
  std::snprintf(line, sizeof line, "%10s %10s %10s %10s %14s %9s %10s\n", "RATE_HZ", "MIN_S",
                "MAX_S", "STD_DEV_S", "BYTES_PER_S", "MESSAGES", "PUBLISHERS");
  return line;
}

std::string topic_hz_line(const json& window) {
  char line[160];
  std::snprintf(line, sizeof line, "%10s %10s %10s %10s %14s %9llu %10llu\n",
                number_or_dash(window.at("rate_hz"), "%.3f").c_str(),
                number_or_dash(window.at("min_s"), "%.6f").c_str(),
                number_or_dash(window.at("max_s"), "%.6f").c_str(),
                number_or_dash(window.at("std_dev_s"), "%.6f").c_str(),
                number_or_dash(window.at("bytes_per_s"), "%.1f").c_str(),
                window.at("messages").get<unsigned long long>(),
                window.at("publishers").get<unsigned long long>());
  return line;
}

int topic_hz(InspectionSource& source, const HzOptions& options, std::ostream& out) {
  HzMeter meter(source, options.topic);
  return stream_windows(
      options, out, topic_hz_header(), [&] { return meter.measure(options.window_s); },
      topic_hz_line);
}

void set_topic_hz_command(CLI::App& topic, Context& context) {
  add_window_command(
      topic, context, "hz",
      "Publish rate, period jitter and payload bandwidth of a topic, one line per window, from "
      "kernel counters, without subscribing; until SIGINT or --count windows",
      topic_hz);
}

}  // namespace agnocast::cli
