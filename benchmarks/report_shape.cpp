#include "report_shape.hpp"

#include <cmath>

namespace agnocast::bench {
namespace {

using json = nlohmann::ordered_json;

bool positive_number(const json& value) {
  return value.is_number() && std::isfinite(value.get<double>()) && value.get<double>() > 0;
}

class Checker {
 public:
  explicit Checker(const json& report) : report_(report) {}

  const json* at(const std::vector<std::string>& path) {
    const json* node = &report_;
    std::string where;
    for (const auto& key : path) {
      where += "/" + key;
      if (!node->is_object() || !node->contains(key) || (*node)[key].is_null()) {
        errors.push_back(where + " is missing");
        return nullptr;
      }
      node = &(*node)[key];
    }
    return node;
  }

  void positive(const std::vector<std::string>& path) {
    const json* value = at(path);
    if (value && !positive_number(*value)) errors.push_back(join(path) + " is not positive");
  }

  void latency(const std::string& who, const std::string& label) {
    const json* stats = at({"latency", who, label});
    if (!stats) return;
    if (!positive_number((*stats)["p50_us"]) || !positive_number((*stats)["p99_us"]) ||
        (*stats)["p99_us"].get<double>() < (*stats)["p50_us"].get<double>() ||
        !positive_number((*stats)["samples"])) {
      errors.push_back("latency/" + who + "/" + label + ": p50, p99 or samples not sane");
    }
  }

  // In icount mode a ratio is one value, without interval.
  void ratio(const std::string& name, bool single) {
    const json* value = at({"ratios", name});
    at({"targets", name});
    if (single) {
      if (value && !positive_number(*value)) errors.push_back("ratio " + name + " not positive");
      return;
    }
    const json* interval = at({"ratio_ci", name});
    if (!value || !interval) return;
    if (!positive_number(*value) || !interval->is_array() || interval->size() != 2 ||
        !positive_number((*interval)[0]) || !positive_number((*interval)[1]) ||
        (*interval)[0].get<double>() > value->get<double>() ||
        value->get<double>() > (*interval)[1].get<double>()) {
      errors.push_back("ratio " + name + ": value or 95 % interval not sane");
    }
  }

  // A side's count: at least `least` calls a message, the named calls among them.
  void syscalls(const std::string& run, const std::string& side, double least,
                const std::vector<std::string>& calls) {
    const json* value = at({"syscalls_per_message", run, side});
    if (value && (!value->is_number() || value->get<double>() < least)) {
      errors.push_back("syscalls_per_message/" + run + "/" + side + " is under " +
                       std::to_string(least));
    }
    for (const auto& call : calls) positive({"syscalls_per_message", run, side + "_by_call", call});
  }

  std::vector<std::string> errors;

 private:
  static std::string join(const std::vector<std::string>& path) {
    std::string text;
    for (const auto& key : path) text += "/" + key;
    return text;
  }
  const json& report_;
};

// Latencies print in µs; in icount mode in ns, which are instructions there.
double unit_per_us = 1;
const char* unit = "µs";

std::string cell(const json& latency, const std::string& who, const std::string& label) {
  if (!latency.contains(who) || latency[who].is_null() || !latency[who].contains(label)) {
    return "—";
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.0f / %.0f",
                latency[who][label]["p50_us"].get<double>() * unit_per_us,
                latency[who][label]["p99_us"].get<double>() * unit_per_us);
  return text;
}

std::string number(const json& value, const char* format = "%.2f") {
  if (!value.is_number()) return "—";
  char text[32];
  std::snprintf(text, sizeof text, format, value.get<double>());
  return text;
}

std::string by_call(const json& calls) {
  std::string text;
  for (const auto& [name, count] : calls.items()) {
    if (!text.empty()) text += ", ";
    text += name + " " + number(count, "%.2g");
  }
  return text;
}

}  // namespace

std::vector<std::string> report_shape_errors(const json& report) {
  Checker check(report);
  const json* mode = check.at({"mode"});
  if (mode && *mode != "icount" && *mode != "ordinary") check.errors.push_back("unknown mode");
  const bool icount = mode && *mode == "icount";
  for (const char* key : {"kernel", "cpu", "system", "clocksource"}) check.at({"machine", key});
  check.positive({"machine", "cpus"});
  const json* rounds = check.at({"rounds"});
  if (rounds && (!rounds->is_number_unsigned() || rounds->get<std::size_t>() < 2 ||
                 (!report["smoke"].get<bool>() && !icount && rounds->get<std::size_t>() < 20))) {
    check.errors.push_back("too few rounds for the intervals");
  }
  const json* failed = check.at({"failed_cells"});
  if (failed && (!failed->is_number_unsigned() || failed->get<std::size_t>() != 0)) {
    check.errors.push_back("series failed or timed out in some rounds");
  }
  check.latency("mqueue_floor", "1 B");
  check.latency("mqueue_epoll_floor", "1 B");
  for (const char* who : {"agnocast", "iceoryx"}) {
    for (const char* size : {"64 B", "4 KiB"}) check.latency(who, size);
  }
  if (!icount) check.latency("agnocast_beside_63_busy_topics", "64 B");
  for (const char* who :
       {"agnocast_constant_bytes", "iceoryx_constant_bytes", "unix_socket_constant_bytes"}) {
    for (const char* size : {"64 B", "4 KiB", "1 MiB", "16 MiB", "64 MiB"}) {
      check.latency(who, size);
    }
  }
  for (const char* who : {"agnocast_fanout", "mqueue_fanout"}) {
    for (const char* subscribers : {"1", "8", "64"}) check.latency(who, subscribers);
  }
  // The slope's difference of p50s may be negative in a tiny smoke run, so
  // fanout_slope is only required to be there.
  for (const char* name : {"size_flatness", "size_flatness_iceoryx", "vs_iceoryx", "vs_iceoryx_64",
                           "vs_mqueue_floor", "vs_epoll_floor", "fanout_64"}) {
    check.ratio(name, icount);
  }
  check.at({"ratios", "fanout_slope"});
  if (!icount) {
    check.ratio("topics_64", false);
    check.ratio("vs_iceoryx_constant_bytes", false);
    check.at({"ratio_ci", "fanout_slope"});
    check.positive({"background", "delivered_per_s"});
  }
  // The seed's protocol: the publisher enters the kernel and wakes each
  // subscriber; the subscriber waits, then enters the kernel.
  for (const char* run : {"qos_10", "qos_1"}) {
    check.syscalls(run, "publisher", 2, {"ioctl", "mq_timedsend"});
    check.syscalls(run, "subscriber", 1, {"ioctl"});
  }
  check.syscalls("qos_10_4_subscribers", "publisher", 5, {"ioctl", "mq_timedsend"});
  for (const char* side : {"publisher", "subscriber"}) {
    const json* allocations = check.at({"allocations_per_message", side});
    if (allocations && (!allocations->is_number() || allocations->get<double>() < 0)) {
      check.errors.push_back(std::string("allocations_per_message/") + side + " is not a count");
    }
  }
  for (const char* who : {"agnocast", "iceoryx", "mqueue_epoll_floor"}) {
    check.positive({"cpu_us_per_message", who, "publisher"});
    check.positive({"cpu_us_per_message", who, "subscriber"});
  }
  check.positive({"throughput", "messages_per_s"});
  return check.errors;
}

void print_markdown(const json& report) {
  const json& machine = report["machine"];
  const bool icount = report.value("mode", "ordinary") == "icount";
  std::printf(
      "Run (%s mode): kernel %s, %s (%s), %lld CPUs, %lld MiB, clocksource %s; %zu rounds%s.\n\n",
      icount ? "icount" : "ordinary", machine["kernel"].get<std::string>().c_str(),
      machine["system"].get<std::string>().c_str(), machine["cpu"].get<std::string>().c_str(),
      machine["cpus"].get<long long>(), machine["memory_mib"].get<long long>(),
      machine["clocksource"].get<std::string>().c_str(), report["rounds"].get<std::size_t>(),
      report["smoke"].get<bool>() ? " (smoke)" : "");
  unit_per_us = icount ? 1000 : 1;
  unit = icount ? "ns (instructions)" : "µs";
  const json& latency = report["latency"];

  std::printf("| one-way latency, %s (p50 / p99) | 64 B | 4 KiB |\n|---|---|---|\n", unit);
  const std::pair<const char*, const char*> plain[] = {
      {"agnocast", "agnocast"},
      {"iceoryx", "iceoryx"},
      {"agnocast_beside_63_busy_topics", "agnocast, 63 other topics at 1 kHz each"},
  };
  for (const auto& [who, title] : plain) {
    std::printf("| %s | %s | %s |\n", title, cell(latency, who, "64 B").c_str(),
                cell(latency, who, "4 KiB").c_str());
  }
  std::printf("| mqueue floor, receiver in `mq_receive` (1 B) | %s | |\n",
              cell(latency, "mqueue_floor", "1 B").c_str());
  std::printf("| mqueue floor, receiver in `epoll_wait` (1 B) | %s | |\n\n",
              cell(latency, "mqueue_epoll_floor", "1 B").c_str());

  std::printf(
      "| one-way latency, %s (p50 / p99), 64 MiB written before each sample | agnocast | "
      "iceoryx | Unix socket (copy) |\n|---|---|---|---|\n",
      unit);
  if (latency.contains("agnocast_constant_bytes")) {
    for (const auto& [label, stats] : latency["agnocast_constant_bytes"].items()) {
      std::printf("| %s | %s | %s | %s |\n", label.c_str(),
                  cell(latency, "agnocast_constant_bytes", label).c_str(),
                  cell(latency, "iceoryx_constant_bytes", label).c_str(),
                  cell(latency, "unix_socket_constant_bytes", label).c_str());
    }
  }

  std::printf(
      "\n| publish to last delivery, %s (p50 / p99) | agnocast, 4 KiB | mqueue wake-ups, "
      "receivers in `epoll_wait` |\n|---|---|---|\n",
      unit);
  if (latency.contains("agnocast_fanout")) {
    for (const auto& [label, stats] : latency["agnocast_fanout"].items()) {
      std::printf("| %s subscriber(s) | %s | %s |\n", label.c_str(),
                  cell(latency, "agnocast_fanout", label).c_str(),
                  cell(latency, "mqueue_fanout", label).c_str());
    }
  }

  if (icount) {
    std::printf("\n| ratio (lower is better) | value | target | met |\n|---|---|---|---|\n");
  } else {
    std::printf(
        "\n| ratio (lower is better) | median of rounds | 95 %% interval | target | met |\n"
        "|---|---|---|---|---|\n");
  }
  for (const auto& [name, value] : report["ratios"].items()) {
    const json& met = report["met"][name];
    const char* met_text = met.is_boolean() ? (met.get<bool>() ? "yes" : "no") : "—";
    if (icount) {
      std::printf("| `%s` | %s | ≤ %s | %s |\n", name.c_str(), number(value, "%.3f").c_str(),
                  number(report["targets"][name], "%g").c_str(), met_text);
      continue;
    }
    const json& interval = report["ratio_ci"][name];
    const std::string range =
        interval.is_array() ? number(interval[0]) + "–" + number(interval[1]) : std::string("—");
    std::printf("| `%s` | %s | %s | ≤ %s | %s |\n", name.c_str(), number(value).c_str(),
                range.c_str(), number(report["targets"][name], "%g").c_str(), met_text);
  }

  std::printf(
      "\n| system calls per message (counted) | publisher | subscriber | publisher's "
      "calls | subscriber's calls |\n|---|---|---|---|---|\n");
  const std::pair<const char*, const char*> runs[] = {
      {"qos_10", "QoS 10, 1 subscriber"},
      {"qos_1", "QoS 1, 1 subscriber"},
      {"qos_10_4_subscribers", "QoS 10, 4 subscribers"},
  };
  for (const auto& [run, title] : runs) {
    const json& counts = report["syscalls_per_message"][run];
    if (counts.is_null()) {
      std::printf("| %s | — | — | | |\n", title);
      continue;
    }
    std::printf("| %s | %s | %s | %s | %s |\n", title, number(counts["publisher"]).c_str(),
                number(counts["subscriber"]).c_str(), by_call(counts["publisher_by_call"]).c_str(),
                by_call(counts["subscriber_by_call"]).c_str());
  }

  std::printf(
      "\n| CPU µs per message at 1 kHz (user + system) | publisher | subscriber |\n"
      "|---|---|---|\n");
  for (const auto& [who, cpu] : report["cpu_us_per_message"].items()) {
    std::printf("| %s | %s | %s |\n", who.c_str(),
                cpu.is_null() ? "—" : number(cpu["publisher"], "%.1f").c_str(),
                cpu.is_null() ? "—" : number(cpu["subscriber"], "%.1f").c_str());
  }

  if (report.contains("allocations_per_message")) {
    const json& allocations = report["allocations_per_message"];
    std::printf(
        "\nHeap allocations per message at 1 kHz (operator new, QoS 10): publisher %s, "
        "subscriber %s.\n",
        number(allocations["publisher"], "%.2f").c_str(),
        number(allocations["subscriber"], "%.2f").c_str());
  }
  const json& slopes = report["fanout_slope_us_per_subscriber"];
  std::printf("\nFan-out slope, µs per extra subscriber: agnocast %s, mqueue wake-ups %s.\n",
              number(slopes["agnocast"], "%.1f").c_str(), number(slopes["mqueue"], "%.1f").c_str());
  if (report.contains("background")) {
    const json& background = report["background"];
    std::printf("Beside 63 busy topics: %s of %s messages/s offered were delivered.\n",
                number(background["delivered_per_s"], "%.0f").c_str(),
                number(background["offered_per_s"], "%.0f").c_str());
  }
  std::printf("Throughput, 64 B back to back: %s messages/s (%llu of %llu received).\n",
              number(report["throughput"]["messages_per_s"], "%.0f").c_str(),
              report["throughput"]["received"].get<unsigned long long>(),
              report["throughput"]["published"].get<unsigned long long>());
}

}  // namespace agnocast::bench
