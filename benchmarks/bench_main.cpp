// agnocast-bench: every measurement of SPEC §9 in one run on one machine, so
// the ratios between agnocast and its yardsticks hold even where absolute
// times do not (the test VM runs under TCG emulation).
#include <sys/utsname.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "agnocast_roles.hpp"
#include "baselines.hpp"
#include "bench_support.hpp"
#include "iceoryx_runner.hpp"

namespace bench = agnocast::bench;
using json = nlohmann::ordered_json;

namespace {

struct Plan {
  std::vector<std::size_t> sizes{64, 4 << 10, 1 << 20, 16 << 20, 64 << 20};
  std::vector<std::size_t> iceoryx_sizes{64, 4 << 10, 1 << 20};
  std::vector<std::size_t> fanouts{1, 8, 64};
  std::size_t fanout_size = 4 << 10;
  std::size_t floor_count = 2000;
  std::size_t throughput_count = 20000;

  std::size_t latency_count(std::size_t size) const {
    if (smoke) return 3;
    return size >= (16u << 20) ? 20 : 300;
  }
  std::size_t fanout_count() const { return smoke ? 3 : 100; }
  std::size_t rounds = 3;  // latency and fan-out rounds; each takes a third of every series
  bool smoke = false;
  std::vector<std::string> only;  // empty: every section

  bool wants(const char* section) const {
    return only.empty() || std::find(only.begin(), only.end(), section) != only.end();
  }

  void make_smoke() {
    smoke = true;
    rounds = 1;
    floor_count = 20;
    throughput_count = 200;
  }
};

json stats_json(const bench::LatencyStats& stats) {
  return {{"p50_us", stats.p50_us}, {"p99_us", stats.p99_us}, {"samples", stats.samples}};
}

// Publish-to-last-delivery: for each message, the slowest subscriber's latency.
std::vector<std::int64_t> last_delivery(
    const std::vector<std::vector<std::int64_t>>& per_subscriber) {
  std::vector<std::int64_t> slowest(per_subscriber.front().size(), 0);
  for (const auto& latencies : per_subscriber) {
    for (std::size_t i = 0; i < slowest.size(); ++i)
      slowest[i] = std::max(slowest[i], latencies[i]);
  }
  return slowest;
}

json machine_json() {
  utsname names{};
  uname(&names);
  std::string cpu = "unknown";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  return {{"kernel", names.release},
          {"cpu", cpu},
          {"cpus", sysconf(_SC_NPROCESSORS_ONLN)},
          {"memory_mib", sysconf(_SC_PHYS_PAGES) / 1024 * sysconf(_SC_PAGE_SIZE) / 1024}};
}

double ratio(double numerator, double denominator) {
  return denominator > 0 ? numerator / denominator : 0;
}

json run(const Plan& plan, const std::string& iceoryx_role) {
  json report;
  report["machine"] = machine_json();
  report["smoke"] = plan.smoke;

  // Latency is measured in rounds, each taking its share of every series, so
  // a slow spell of the emulator falls on all series alike instead of on
  // whichever ran during it; the ratios compare neighbours in time.
  std::map<std::string, std::map<std::string, std::vector<std::int64_t>>> samples;
  std::vector<std::pair<std::string, std::string>> order;  // first-seen order of the series
  auto add = [&](const std::string& who, const std::string& label, std::vector<std::int64_t> more) {
    auto [series, inserted] = samples[who].try_emplace(label);
    if (inserted) order.emplace_back(who, label);
    series->second.insert(series->second.end(), more.begin(), more.end());
  };
  auto share = [&](std::size_t count) { return (count + plan.rounds - 1) / plan.rounds; };

  std::optional<bench::IceoryxRunner> iceoryx =
      plan.wants("iceoryx") ? bench::IceoryxRunner::start(iceoryx_role) : std::nullopt;
  if (plan.wants("iceoryx") && !iceoryx) {
    std::cerr << "iceoryx not found (iox-roudi or " << iceoryx_role << "): skipped\n";
  }
  const bool latency_wanted = plan.wants("floor") || plan.wants("latency") || iceoryx;
  for (std::size_t round = 1; round <= plan.rounds && latency_wanted; ++round) {
    std::cerr << "latency round " << round << " of " << plan.rounds << "...\n";
    if (plan.wants("floor")) {
      add("mqueue_floor", "1 B", bench::run_mqueue_floor(share(plan.floor_count)));
    }
    for (std::size_t size : plan.sizes) {
      if (!plan.wants("latency")) break;
      const std::string label = bench::format_size(size);
      const std::size_t count = share(plan.latency_count(size));
      add("agnocast", label, bench::run_agnocast_latency(size, count, 1).front());
      if (plan.wants("copy")) add("unix_socket", label, bench::run_unix_socket_copy(size, count));
    }
    if (plan.wants("latency")) {
      // The same 64 B message after writing 64 MiB elsewhere: how much of the
      // growth with size is the caches the large write evicted.
      add("agnocast_after_64_mib_write", "64 B",
          bench::run_agnocast_latency(64, share(plan.latency_count(64 << 20)), 1, 64 << 20)
              .front());
    }
    for (std::size_t size : plan.iceoryx_sizes) {
      if (!iceoryx) break;
      add("iceoryx", bench::format_size(size),
          iceoryx->measure(size, share(plan.latency_count(size))));
    }
  }
  for (const auto& [who, label] : order) {
    report["latency"][who][label] = stats_json(bench::summarize(samples[who][label]));
  }
  if (!iceoryx) report["latency"]["iceoryx"] = nullptr;

  if (plan.wants("throughput")) {
    std::cerr << "throughput...\n";
    auto throughput = bench::run_agnocast_throughput(64, plan.throughput_count);
    report["throughput"] = {{"size_bytes", 64},
                            {"published", throughput.published},
                            {"received", throughput.received},
                            {"messages_per_s", throughput.messages_per_s}};
  }

  // Fan-out in rounds too, for the same reason as latency.
  std::map<std::size_t, std::vector<std::int64_t>> fanout_samples;
  for (std::size_t round = 1; round <= plan.rounds && plan.wants("fanout"); ++round) {
    for (std::size_t subscribers : plan.fanouts) {
      std::cerr << "fan-out to " << subscribers << " subscribers, round " << round << "...\n";
      auto slowest = last_delivery(
          bench::run_agnocast_latency(plan.fanout_size, share(plan.fanout_count()), subscribers));
      auto& series = fanout_samples[subscribers];
      series.insert(series.end(), slowest.begin(), slowest.end());
    }
  }
  for (std::size_t subscribers : plan.fanouts) {
    if (!fanout_samples.contains(subscribers)) continue;
    report["fanout"][std::to_string(subscribers)] =
        stats_json(bench::summarize(fanout_samples[subscribers]));
  }

  auto p50 = [&](const char* who, const char* size) -> double {
    if (!report.contains("latency") || !report["latency"].contains(who)) return 0;
    const json& entry = report["latency"][who];
    if (entry.is_null() || !entry.contains(size)) return 0;
    return entry[size]["p50_us"].get<double>();
  };
  auto fanout_p50 = [&](const char* n) -> double {
    if (!report.contains("fanout") || !report["fanout"].contains(n)) return 0;
    return report["fanout"][n]["p50_us"].get<double>();
  };
  report["ratios"] = {
      {"size_flatness", ratio(p50("agnocast", "64 MiB"), p50("agnocast", "64 B"))},
      // The same, against a 64 B message sent after an equally large write.
      {"size_flatness_cache_controlled",
       ratio(p50("agnocast", "64 MiB"), p50("agnocast_after_64_mib_write", "64 B"))},
      {"vs_iceoryx", ratio(p50("agnocast", "4 KiB"), p50("iceoryx", "4 KiB"))},
      {"vs_mqueue_floor", ratio(p50("agnocast", "64 B"), p50("mqueue_floor", "1 B"))},
      {"fanout_64", ratio(fanout_p50("64"), fanout_p50("1"))},
  };
  report["targets"] = {{"size_flatness", 1.05},
                       {"size_flatness_cache_controlled", 1.05},
                       {"vs_iceoryx", 1.0},
                       {"vs_mqueue_floor", 1.3},
                       {"fanout_64", 64.0}};
  return report;
}

void print_table(const json& report) {
  std::printf("machine: %s, %lld CPUs, kernel %s\n",
              report["machine"]["cpu"].get<std::string>().c_str(),
              report["machine"]["cpus"].get<long long>(),
              report["machine"]["kernel"].get<std::string>().c_str());
  std::printf("\none-way latency, microseconds (p50 / p99)\n");
  std::printf("%-10s %-22s %-22s %-22s\n", "payload", "agnocast", "unix socket (copy)", "iceoryx");
  const json none = json::object();
  const json& latency = report.contains("latency") ? report["latency"] : none;
  const json& agnocast_latency = latency.contains("agnocast") ? latency["agnocast"] : none;
  for (const auto& [label, agnocast] : agnocast_latency.items()) {
    auto cell = [&](const json& entry) {
      if (entry.is_null() || !entry.contains(label)) return std::string("-");
      char text[64];
      std::snprintf(text, sizeof text, "%.1f / %.1f", entry[label]["p50_us"].get<double>(),
                    entry[label]["p99_us"].get<double>());
      return std::string(text);
    };
    auto column = [&](const char* who) {
      return cell(latency.contains(who) ? latency[who] : none);
    };
    std::printf("%-10s %-22s %-22s %-22s\n", label.c_str(), column("agnocast").c_str(),
                column("unix_socket").c_str(), column("iceoryx").c_str());
  }
  if (latency.contains("agnocast_after_64_mib_write")) {
    const json& control = latency["agnocast_after_64_mib_write"]["64 B"];
    std::printf("agnocast 64 B after a 64 MiB write (cache control): %.1f / %.1f\n",
                control["p50_us"].get<double>(), control["p99_us"].get<double>());
  }
  if (latency.contains("mqueue_floor")) {
    const json& floor = latency["mqueue_floor"]["1 B"];
    std::printf("mqueue notification floor (1 B): %.1f / %.1f\n", floor["p50_us"].get<double>(),
                floor["p99_us"].get<double>());
  }
  if (report.contains("throughput")) {
    std::printf("\nthroughput (64 B): %.0f messages/s (%llu of %llu received)\n",
                report["throughput"]["messages_per_s"].get<double>(),
                report["throughput"]["received"].get<unsigned long long>(),
                report["throughput"]["published"].get<unsigned long long>());
  }
  std::printf("\npublish to last delivery, 4 KiB, microseconds (p50 / p99)\n");
  for (const auto& [subscribers, stats] :
       (report.contains("fanout") ? report["fanout"] : none).items()) {
    std::printf("%3s subscriber(s): %.1f / %.1f\n", subscribers.c_str(),
                stats["p50_us"].get<double>(), stats["p99_us"].get<double>());
  }
  std::printf("\nratio                            measured   target (lower is better)\n");
  for (const auto& [name, value] : report["ratios"].items()) {
    std::printf("%-32s %8.3f   %6.2f\n", name.c_str(), value.get<double>(),
                report["targets"][name].get<double>());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"agnocast-bench: latency, throughput and fan-out against iceoryx and baselines"};
  bool json_output = false, smoke = false;
  std::string iceoryx_role =
      (std::filesystem::read_symlink("/proc/self/exe").parent_path() / "agnocast-bench-iceoryx")
          .string();
  app.add_flag("--json", json_output, "print one JSON object instead of tables");
  app.add_flag("--smoke", smoke, "tiny counts: checks that every measurement works");
  app.add_option("--iceoryx-role", iceoryx_role, "the iceoryx role program");
  Plan plan;
  std::vector<std::string> size_texts;
  app.add_option("--only", plan.only, "run only these sections (default: all)")
      ->check(CLI::IsMember({"floor", "latency", "copy", "iceoryx", "throughput", "fanout"}));
  app.add_option("--sizes", size_texts, "payload sizes for the latency sections, e.g. 64 4K 1M");
  CLI11_PARSE(app, argc, argv);

  if (smoke) plan.make_smoke();
  if (!size_texts.empty()) {
    plan.sizes.clear();
    for (const auto& text : size_texts) plan.sizes.push_back(bench::parse_size(text));
  }
  try {
    json report = run(plan, iceoryx_role);
    if (json_output) {
      std::cout << report.dump() << "\n";
    } else {
      print_table(report);
    }
  } catch (const std::exception& error) {
    std::cerr << "agnocast-bench: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
