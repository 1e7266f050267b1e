// agnocast-bench: every measurement in one run on one machine, so
// the ratios between agnocast and its yardsticks hold even where absolute
// times do not (the test VM runs under TCG emulation on a shared host).
#include <poll.h>
#include <sys/personality.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <agnocast/limits.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <regex>
#include <sstream>

#include "agnocast_roles.hpp"
#include "baselines.hpp"
#include "bench_support.hpp"
#include "iceoryx_runner.hpp"
#include "kernel_memory.hpp"
#include "readme_plots.hpp"
#include "recording.hpp"
#include "report_shape.hpp"
#include "round_estimate.hpp"

namespace bench = agnocast::bench;
using json = nlohmann::ordered_json;

namespace {

struct Plan {
  std::vector<std::size_t> sizes{64, 4 << 10, 1 << 20, 16 << 20, 64 << 20};
  std::vector<std::size_t> fanouts{1, 8, 64};
  // icount mode's fan-out points: its rounds are cheap, and the publisher's
  // publish() call is fitted over them.
  std::vector<std::size_t> icount_fanouts{1, 2, 4, 8, 16, 32, 64};
  // Scale: other topics registered (idle), and processes attached in all
  // (the measured publisher and subscriber among them). In icount mode (a
  // smoke run measures their smallest points): what they show is
  // instructions, which the ordinary mode's noise hides.
  std::vector<std::size_t> idle_topics{1, 100, 1000, 10000};
  std::vector<std::size_t> attached_processes{2, 50, 200};
  // QoS depths of both sides: the one-way latency, and the publisher's
  // publish() call into a subscriber that takes every message or never does
  // (its queue full, so each publish drops the oldest). The last is the
  // limit, qos_depth_max.
  std::vector<std::size_t> depths{1, 10, 100, agnocast::qos_depth_max};
  // The publish() call into full depth-1 queues of this many polling
  // subscribers: one, and the limit of a topic.
  std::vector<std::size_t> full_queue_subscribers{1, agnocast::subscribers_per_topic_max};
  // The one-way latency beside this many other publishers of the topic:
  // none, and the limit of a topic less the measured one.
  std::vector<std::size_t> other_publishers{0, agnocast::publishers_per_topic_max - 1};
  // Objects of each kind whose kernel memory is measured (a process may hold
  // 1,024 endpoints by default, and four kinds are made).
  std::size_t memory_objects = 250;
  // Request and response payloads of the service's round trip.
  std::vector<std::size_t> service_sizes{64, 4 << 20};
  std::size_t rounds = 20;
  std::size_t latency_samples = 9;         // per series and round
  std::size_t constant_bytes_samples = 2;  // each writes 64 MiB first
  std::size_t fanout_samples = 5;
  std::size_t steady_messages = 1000;  // at 1 kHz
  // Messages back to back: 64 B ones, and 4 MiB ones (each written whole);
  // repeated for an interval in the ordinary mode.
  std::size_t throughput_count = 20000;
  std::size_t large_throughput_count = 200;
  std::size_t throughput_repeats = 7;
  std::size_t background_topics = 63;
  std::uint64_t seed = 1;
  bool smoke = false;
  // QEMU's instruction-counting mode: guest time is instructions executed,
  // on one vCPU, so every p50 repeats to the nanosecond and a few rounds
  // suffice; series that need parallel cores are left to the ordinary mode.
  bool icount = false;
  // What the VM cannot see of where it runs, passed in by scripts/bench.
  std::string host_cpu, qemu_version, qemu_flags;
  // Only the series whose names match (--series), and the cost breakdown
  // when "cost_breakdown" matches; empty: every series, and the rest of the
  // report (system calls, CPU, throughput, recording), which a selection
  // leaves out.
  std::string series;
  bool selected(const std::string& who) const {
    return series.empty() || std::regex_search(who, std::regex(series));
  }

  void make_smoke() {
    smoke = true;
    rounds = 2;
    latency_samples = 2;
    constant_bytes_samples = 1;
    fanout_samples = 1;
    service_sizes = {64};
    idle_topics = {100};
    attached_processes = {4};
    depths = {10};
    full_queue_subscribers = {2};
    other_publishers = {3};
    memory_objects = 20;
    steady_messages = 30;
    throughput_count = 200;
    large_throughput_count = 10;
    throughput_repeats = 2;
  }
};

// A series' round p50 or, for `all_rounds`, the p50 of all its rounds together.
constexpr std::size_t all_rounds = std::numeric_limits<std::size_t>::max();

// One short series of one round: which series it adds to and how it runs.
// `extra` receives what a series measures besides latencies.
struct Cell {
  std::string who;
  std::string label;
  std::function<std::vector<std::int64_t>(std::vector<std::int64_t>& extra)> run;
};

// What the senders recorded of one cell's samples (SampleWindows): one map
// of name to value per sample, the measured ones last.
std::vector<std::map<std::string, std::int64_t>> read_windows(const std::string& path) {
  std::vector<std::map<std::string, std::int64_t>> windows;
  std::ifstream file(path);
  std::string line;
  while (std::getline(file, line)) {
    std::map<std::string, std::int64_t> values;
    std::istringstream fields(line);
    std::string field;
    while (fields >> field) {
      const auto equals = field.find('=');
      if (equals == std::string::npos) continue;
      try {
        values[field.substr(0, equals)] = std::stoll(field.substr(equals + 1));
      } catch (const std::exception&) {
      }
    }
    windows.push_back(std::move(values));
  }
  return windows;
}

// Runs a cell in a child process of its own process group, so that a role
// that hangs (a peer died while it waited) costs one cell of one round, not
// the run: after `limit_s` the whole group is killed and the cell has no
// samples.  False then.
bool run_isolated(const Cell& cell, int limit_s, std::vector<std::int64_t>& samples,
                  std::vector<std::int64_t>& extra) {
  bench::Pipe results = bench::Pipe::open();
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    setpgid(0, 0);
    results.close_read();
    int status = 1;
    try {
      std::vector<std::int64_t> more;
      const std::vector<std::int64_t> measured = cell.run(more);
      bench::send_latencies(results.write_fd, measured);
      bench::send_latencies(results.write_fd, more);
      status = 0;
    } catch (const std::exception& error) {
      std::cerr << "agnocast-bench: " << cell.who << " " << cell.label << ": " << error.what()
                << "\n";
    }
    _exit(status);
  }
  setpgid(child, child);
  results.close_write();
  pollfd ready{results.read_fd, POLLIN, 0};
  const bool answered = poll(&ready, 1, limit_s * 1000) == 1;
  if (answered) {
    samples = bench::receive_latencies(results.read_fd);
    extra = bench::receive_latencies(results.read_fd);
  } else {
    kill(-child, SIGKILL);
  }
  results.close_read();
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  const bool ok = answered && WIFEXITED(status) && WEXITSTATUS(status) == 0 && !samples.empty();
  if (!ok) {
    kill(-child, SIGKILL);  // whatever of its group is left
    std::cerr << "agnocast-bench: " << cell.who << " " << cell.label
              << (answered ? " failed" : " timed out") << "; this round has none of it\n";
    samples.clear();
    extra.clear();
  }
  return ok;
}

// Samples of every series, kept per round so that ratios pair neighbours in time.
class Samples {
 public:
  void add(std::size_t round, const std::string& who, const std::string& label,
           const std::vector<std::int64_t>& samples) {
    auto& rounds = by_round_[{who, label}];
    rounds.resize(std::max(rounds.size(), round + 1));
    rounds[round].insert(rounds[round].end(), samples.begin(), samples.end());
  }
  bool has(const std::string& who, const std::string& label) const {
    return by_round_.contains({who, label});
  }
  // p50 of that series in that round, or of all rounds (`all_rounds`), in µs;
  // NaN when it has none.
  double round_p50(std::size_t round, const std::string& who, const std::string& label) const {
    if (round == all_rounds) {
      // A series whose every cell failed has rounds but no samples.
      return has(who, label) && pooled(who, label).samples > 0
                 ? pooled(who, label).p50_us
                 : std::numeric_limits<double>::quiet_NaN();
    }
    auto found = by_round_.find({who, label});
    if (found == by_round_.end() || round >= found->second.size() || found->second[round].empty()) {
      return std::numeric_limits<double>::quiet_NaN();
    }
    return bench::summarize(found->second[round]).p50_us;
  }
  std::size_t rounds(const std::string& who, const std::string& label) const {
    return by_round_.at({who, label}).size();
  }
  bench::LatencyStats pooled(const std::string& who, const std::string& label) const {
    std::vector<std::int64_t> all;
    for (const auto& round : by_round_.at({who, label})) {
      all.insert(all.end(), round.begin(), round.end());
    }
    return bench::summarize(std::move(all));
  }

 private:
  std::map<std::pair<std::string, std::string>, std::vector<std::vector<std::int64_t>>> by_round_;
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

std::string first_line_of(const char* path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  return line;
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
  return {
      {"kernel", names.release},
      {"cpu", cpu},
      {"cpus", sysconf(_SC_NPROCESSORS_ONLN)},
      {"memory_mib", sysconf(_SC_PHYS_PAGES) / 1024 * sysconf(_SC_PAGE_SIZE) / 1024},
      {"system", first_line_of("/sys/devices/virtual/dmi/id/sys_vendor") + " " +
                     first_line_of("/sys/devices/virtual/dmi/id/product_name")},
      {"clocksource",
       first_line_of("/sys/devices/system/clocksource/clocksource0/current_clocksource")},
      {"address_randomization", (personality(0xffffffff) & ADDR_NO_RANDOMIZE) == 0 &&
                                    first_line_of("/proc/sys/kernel/randomize_va_space") != "0"}};
}

// A ratio measured in every round: numerator / denominator of that round's
// p50s (or of the pooled p50s).  Its target differs between the modes; NaN:
// not reported in that mode.
struct RoundRatio {
  const char* name;
  double target;
  double icount_target;
  std::function<double(std::size_t round)> of_round;
};
constexpr double not_in_mode = std::numeric_limits<double>::quiet_NaN();

// Per-message counts; `pacing` names the benchmark's own pacing call, left out.
json counts_json(const bench::SyscallCounts& counts, const std::string& pacing) {
  const double messages = static_cast<double>(counts.at("messages"));
  std::int64_t named = 0;
  json by_call = json::object();
  for (const auto& [name, count] : counts) {
    if (name == "messages" || name == "total" || name == pacing || count == 0) continue;
    by_call[name] = static_cast<double>(count) / messages;
    named += count;
  }
  const std::int64_t pacing_calls = counts.contains(pacing) ? counts.at(pacing) : 0;
  const std::int64_t other = counts.at("total") - named - pacing_calls;
  if (other != 0) by_call["other"] = static_cast<double>(other) / messages;
  return {{"per_message", static_cast<double>(counts.at("total") - pacing_calls) / messages},
          {"by_call", by_call},
          {"messages", counts.at("messages")}};
}

json syscalls_json(const bench::SteadyResult& steady) {
  if (!steady.publisher || !steady.subscriber) return nullptr;
  // The publisher's clock_nanosleep is the benchmark's 1 kHz pacing, not agnocast's.
  json publisher = counts_json(*steady.publisher, "clock_nanosleep");
  json subscriber = counts_json(*steady.subscriber, "");
  return {{"publisher", publisher["per_message"]},
          {"subscriber", subscriber["per_message"]},
          {"publisher_by_call", publisher["by_call"]},
          {"subscriber_by_call", subscriber["by_call"]},
          {"messages", subscriber["messages"]}};
}

// agnocast-bench-breakdown's report, run as a program of its own (it
// replaces the C library's calls libagnocast makes); null when it fails.
// `what`: its options for what to time ("--service"), or none.
json cost_breakdown(const std::string& program, bool smoke, const std::string& what = "") {
  const std::string command = program + what + (smoke ? " --count 5 --rounds 5" : "");
  FILE* output = popen(command.c_str(), "r");
  if (!output) return nullptr;
  std::string text;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, output)) text.append(buffer, n);
  if (pclose(output) != 0) {
    std::cerr << "agnocast-bench: " << program << " failed\n";
    return nullptr;
  }
  try {
    return json::parse(text);
  } catch (const std::exception& error) {
    std::cerr << "agnocast-bench: " << program << ": " << error.what() << "\n";
    return nullptr;
  }
}

// Messages back to back, agnocast and iceoryx in turn, `plan.throughput_repeats`
// times: per system and size the median rate (its 95 % interval over the
// repeats when there are several), and agnocast's rate over iceoryx's,
// paired by repeat (higher is better).  In icount mode a second is 10^9
// instructions.
json throughput_json(const Plan& plan, bench::IceoryxRunner* iceoryx) {
  json throughput;
  throughput["repeats"] = plan.throughput_repeats;
  const std::vector<std::pair<std::size_t, std::size_t>> runs{
      {64, plan.throughput_count}, {std::size_t{4} << 20, plan.large_throughput_count}};
  auto summary = [&](const std::vector<double>& values) {
    const bench::RoundEstimate estimate = bench::estimate_over_rounds(values);
    json value = {{"value", estimate.value}};
    value["interval"] = values.size() > 1 ? json{estimate.low, estimate.high} : json();
    return value;
  };
  for (const auto& [size, count] : runs) {
    const std::string label = bench::format_size(size);
    std::vector<double> agnocast_rates, iceoryx_rates, ratios;
    std::uint64_t received = 0, iceoryx_received = 0;
    for (std::size_t repeat = 0; repeat < plan.throughput_repeats; ++repeat) {
      const bench::Throughput agnocast = bench::run_agnocast_throughput(size, count);
      agnocast_rates.push_back(agnocast.messages_per_s);
      received += agnocast.received;
      if (!iceoryx) continue;
      const bench::Throughput other = iceoryx->throughput(size, count);
      iceoryx_rates.push_back(other.messages_per_s);
      iceoryx_received += other.received;
      ratios.push_back(agnocast.messages_per_s / other.messages_per_s);
    }
    const double published = static_cast<double>(count * plan.throughput_repeats);
    json agnocast_json = summary(agnocast_rates);
    agnocast_json["published"] = count;
    agnocast_json["received_fraction"] = static_cast<double>(received) / published;
    throughput["agnocast"][label] = agnocast_json;
    if (iceoryx) {
      json iceoryx_json = summary(iceoryx_rates);
      iceoryx_json["published"] = count;
      iceoryx_json["received_fraction"] = static_cast<double>(iceoryx_received) / published;
      throughput["iceoryx"][label] = iceoryx_json;
      throughput["vs_iceoryx"][label] = summary(ratios);
    } else {
      throughput["iceoryx"][label] = nullptr;
    }
  }
  return throughput;
}

json cpu_json(const bench::CpuPerMessage& cpu) {
  return {{"publisher", cpu.publisher_us}, {"subscriber", cpu.subscriber_us}};
}

// The Python subscriber, when this system has it (the agnocast package built
// and an interpreter with numpy: the VM gets both from scripts/bench).
std::optional<bench::PythonSubscriber> find_python(bench::PythonSubscriber python) {
  if (python.package_path.empty() || !std::filesystem::exists(python.script) ||
      !std::filesystem::exists(python.package_path + "/agnocast")) {
    return std::nullopt;
  }
  const std::string probe = python.interpreter + " -c 'import numpy' >/dev/null 2>&1";
  if (std::system(probe.c_str()) != 0) return std::nullopt;
  return python;
}

json run(const Plan& plan, const std::string& iceoryx_role, const std::string& breakdown_program,
         const std::string& cli, const bench::PythonSubscriber& python_subscriber) {
  json report;
  report["mode"] = plan.icount ? "icount" : "ordinary";
  report["machine"] = machine_json();
  report["host"] = {
      {"cpu", plan.host_cpu}, {"qemu", plan.qemu_version}, {"qemu_flags", plan.qemu_flags}};
  report["smoke"] = plan.smoke;
  report["rounds"] = plan.rounds;
  report["seed"] = plan.seed;

  const bool want_iceoryx = plan.selected("iceoryx") || plan.selected("iceoryx_constant_bytes");
  std::optional<bench::IceoryxRunner> iceoryx =
      want_iceoryx ? bench::IceoryxRunner::start(iceoryx_role) : std::nullopt;
  if (want_iceoryx && !iceoryx) {
    std::cerr << "iceoryx not found (iox-roudi or " << iceoryx_role << "): skipped\n";
  }
  const bool want_python = plan.selected("python_subscriber_constant_bytes");
  const std::optional<bench::PythonSubscriber> python =
      want_python ? find_python(python_subscriber) : std::nullopt;
  if (want_python && !python) {
    std::cerr << "Python subscriber not found (" << python_subscriber.interpreter << " with numpy, "
              << python_subscriber.script << ", the agnocast package): skipped\n";
  }

  // Every round runs every series briefly, in its own shuffled order, so a
  // slow spell of the emulator or of the host falls on a few series of one
  // round, and each ratio pairs two series measured close together.
  const std::int64_t started_ns = bench::now_ns();
  Samples samples;
  std::vector<double> background_rates;
  std::size_t failed_cells = 0;
  constexpr int cell_limit_s = 180;
  std::mt19937_64 shuffle(plan.seed);
  const std::string small = bench::format_size(64), page = bench::format_size(4 << 10);
  struct SendCalls {
    std::vector<double> send_us;
    std::vector<double> send_cpu_us;  // the sending thread's own CPU time in the call
    std::size_t delivered_first = 0;  // the receiver had it before the call returned
  };
  std::map<std::string, std::map<std::string, SendCalls>> send_calls;
  const std::string windows_path = "/tmp/agnocast-bench-windows-" + std::to_string(getpid());
  for (std::size_t round = 0; round < plan.rounds; ++round) {
    std::vector<Cell> cells;
    const std::size_t n = plan.latency_samples;
    cells.push_back({"mqueue_floor", "1 B", [&](auto&) {
                       return bench::run_mqueue_floor(n, bench::FloorWait::blocking);
                     }});
    cells.push_back({"mqueue_epoll_floor", "1 B",
                     [&](auto&) { return bench::run_mqueue_floor(n, bench::FloorWait::epoll); }});
    for (std::size_t size : {std::size_t{64}, std::size_t{4} << 10}) {
      cells.push_back({"agnocast", bench::format_size(size), [&, size](auto&) {
                         return bench::run_agnocast_latency(size, n, 1).front();
                       }});
      if (iceoryx) {
        cells.push_back({"iceoryx", bench::format_size(size),
                         [&, size](auto&) { return iceoryx->measure(size, n, 0); }});
      }
    }
    // Request → response: a service's round trip, as many bytes written
    // before each sample for every size, beside two one-way publishes and
    // the Unix socket's request/response floor.
    for (std::size_t size : plan.service_sizes) {
      const std::size_t scratch = plan.service_sizes.back() - size;
      cells.push_back({"agnocast_service", bench::format_size(size),
                       [=](auto&) { return bench::run_agnocast_round_trip(size, n, scratch); }});
    }
    cells.push_back(
        {"agnocast_ping_pong", small, [=](auto&) { return bench::run_agnocast_ping_pong(64, n); }});
    cells.push_back({"unix_socket_request_response", "1 B",
                     [=](auto&) { return bench::run_unix_socket_request_response(n); }});
    // 63 topics of traffic beside the measured one need cores of their own:
    // on icount's single vCPU the measured message would wait for them.
    if (!plan.icount) {
      cells.push_back(
          {"agnocast_beside_63_busy_topics", small,
           [&](std::vector<std::int64_t>& delivered_per_s) {
             bench::BackgroundTraffic background(plan.background_topics, bench::steady_period_ns);
             auto latencies = bench::run_agnocast_latency(64, n, 1).front();
             delivered_per_s.push_back(static_cast<std::int64_t>(background.delivered_per_s()));
             return latencies;
           }});
    }
    const std::size_t m = plan.constant_bytes_samples;
    for (std::size_t size : plan.sizes) {
      const std::size_t scratch = bench::constant_written_bytes - size;
      const std::string label = bench::format_size(size);
      cells.push_back(
          {"agnocast_constant_bytes", label, [=](auto&) {
             return bench::run_agnocast_latency(size, m, 1, {.scratch_bytes = scratch}).front();
           }});
      if (iceoryx) {
        cells.push_back({"iceoryx_constant_bytes", label,
                         [&, size, scratch](auto&) { return iceoryx->measure(size, m, scratch); }});
      }
      cells.push_back({"unix_socket_constant_bytes", label,
                       [=](auto&) { return bench::run_unix_socket_copy(size, m, scratch); }});
    }
    // A C++ publisher to a Python callback, with the same 64 MiB written
    // before each sample: the smallest and the largest size.
    if (python) {
      for (std::size_t size : {plan.sizes.front(), plan.sizes.back()}) {
        const std::size_t scratch = bench::constant_written_bytes - size;
        cells.push_back({"python_subscriber_constant_bytes", bench::format_size(size),
                         [&, size, scratch](auto&) {
                           return bench::run_python_latency(*python, size, m, scratch);
                         }});
      }
    }
    if (plan.icount || plan.smoke) {
      for (std::size_t topics : plan.idle_topics) {
        cells.push_back({"agnocast_beside_idle_topics", std::to_string(topics), [=](auto&) {
                           // The module's default max_endpoints_per_process is
                           // 1024: a process holds 1,000 of them at most.
                           const bench::IdleEndpoints idle((topics + 999) / 1000, topics);
                           return bench::run_agnocast_latency(64, n, 1).front();
                         }});
      }
      for (std::size_t processes : plan.attached_processes) {
        cells.push_back({"agnocast_with_processes_attached", std::to_string(processes), [=](auto&) {
                           const std::size_t others = processes > 2 ? processes - 2 : 0;
                           const bench::IdleEndpoints idle(others, others);
                           return bench::run_agnocast_latency(64, n, 1).front();
                         }});
      }
    }
    if (plan.icount || plan.smoke) {
      for (std::size_t depth : plan.depths) {
        const std::string label = std::to_string(depth);
        cells.push_back({"agnocast_depth", label, [=](auto&) {
                           return bench::run_agnocast_latency(64, n, 1, {.depth = depth}).front();
                         }});
        cells.push_back({"agnocast_publish_taken", label, [=](auto&) {
                           return bench::run_agnocast_publish_call(depth, 1, n, false);
                         }});
        cells.push_back({"agnocast_publish_into_full_queue", label, [=](auto&) {
                           return bench::run_agnocast_publish_call(depth, 1, n, true);
                         }});
      }
      for (std::size_t subscribers : plan.full_queue_subscribers) {
        cells.push_back(
            {"agnocast_publish_into_full_queues", std::to_string(subscribers),
             [=](auto&) { return bench::run_agnocast_publish_call(1, subscribers, n, true); }});
      }
      for (std::size_t publishers : plan.other_publishers) {
        cells.push_back(
            {"agnocast_beside_other_publishers", std::to_string(publishers), [=](auto&) {
               const std::string topic = "/bench/other_publishers_" + std::to_string(getpid());
               const auto idle = bench::IdleEndpoints::publishers_of(topic, publishers);
               return bench::run_agnocast_latency(64, n, 1, {.topic = topic}).front();
             }});
      }
      // The longest topic name the library takes.
      cells.push_back({"agnocast_longest_topic_name", small, [=](auto&) {
                         const std::string topic =
                             "/" + std::string(agnocast::topic_name_max - 1, 'n');
                         return bench::run_agnocast_latency(64, n, 1, {.topic = topic}).front();
                       }});
    }
    for (std::size_t subscribers : plan.fanouts) {
      const std::string label = std::to_string(subscribers);
      cells.push_back({"agnocast_fanout", label, [&, subscribers](auto&) {
                         return last_delivery(bench::run_agnocast_latency(
                             4 << 10, plan.fanout_samples, subscribers));
                       }});
      cells.push_back({"mqueue_fanout", label, [&, subscribers](auto&) {
                         return bench::run_mqueue_fanout(subscribers, plan.fanout_samples);
                       }});
    }
    std::erase_if(cells, [&](const Cell& cell) { return !plan.selected(cell.who); });
    std::shuffle(cells.begin(), cells.end(), shuffle);
    std::cerr << "round " << round + 1 << " of " << plan.rounds << ": " << cells.size()
              << " series, " << (bench::now_ns() - started_ns) / 1'000'000'000 << " s so far\n";
    for (const Cell& cell : cells) {
      // In the ordinary mode the 64 MiB-written series also time the
      // sender's send call (one clock read after it returns), which the
      // roles append to a file: whether the receiver had the message before
      // it returned tells a stalled sender from a slow path.
      // The fan-out series times the publisher's publish() too, in both modes.
      const bool timed =
          (!plan.icount && cell.who.ends_with("_constant_bytes")) || cell.who == "agnocast_fanout";
      if (timed) {
        std::remove(windows_path.c_str());
        setenv("AGNOCAST_BENCH_WINDOWS", "times", 1);
        setenv("AGNOCAST_BENCH_WINDOWS_FILE", windows_path.c_str(), 1);
      }
      std::vector<std::int64_t> measured, extra;
      if (!run_isolated(cell, cell_limit_s, measured, extra)) ++failed_cells;
      if (timed) {
        unsetenv("AGNOCAST_BENCH_WINDOWS");
        unsetenv("AGNOCAST_BENCH_WINDOWS_FILE");
        const auto windows = read_windows(windows_path);
        SendCalls& calls = send_calls[cell.who][cell.label];
        for (std::size_t i = 0; i < measured.size() && windows.size() >= measured.size(); ++i) {
          const auto& window = windows[windows.size() - measured.size() + i];
          if (!window.contains("send_ns")) continue;
          calls.send_us.push_back(static_cast<double>(window.at("send_ns")) / 1000);
          if (window.contains("send_cpu_ns")) {
            calls.send_cpu_us.push_back(static_cast<double>(window.at("send_cpu_ns")) / 1000);
          }
          if (measured[i] < window.at("send_ns")) ++calls.delivered_first;
        }
      }
      samples.add(round, cell.who, cell.label, measured);
      for (std::int64_t rate : extra) background_rates.push_back(static_cast<double>(rate));
    }
  }

  // Series in a fixed order, sizes and subscriber counts ascending.
  const std::string smallest_label = bench::format_size(plan.sizes.front());
  const std::string largest_label = bench::format_size(plan.sizes.back());
  std::vector<std::string> size_labels, fanout_labels, service_labels, topics_labels,
      processes_labels, depth_labels, full_queues_labels, publishers_labels;
  auto labels_of = [](const std::vector<std::size_t>& counts) {
    std::vector<std::string> labels;
    for (std::size_t count : counts) labels.push_back(std::to_string(count));
    return labels;
  };
  depth_labels = labels_of(plan.depths);
  full_queues_labels = labels_of(plan.full_queue_subscribers);
  publishers_labels = labels_of(plan.other_publishers);
  for (std::size_t size : plan.sizes) size_labels.push_back(bench::format_size(size));
  for (std::size_t topics : plan.idle_topics) topics_labels.push_back(std::to_string(topics));
  for (std::size_t processes : plan.attached_processes) {
    processes_labels.push_back(std::to_string(processes));
  }
  for (std::size_t size : plan.service_sizes) service_labels.push_back(bench::format_size(size));
  for (std::size_t subscribers : plan.fanouts) fanout_labels.push_back(std::to_string(subscribers));
  const std::vector<std::pair<std::string, std::vector<std::string>>> series{
      {"mqueue_floor", {"1 B"}},
      {"mqueue_epoll_floor", {"1 B"}},
      {"agnocast", {small, page}},
      {"iceoryx", {small, page}},
      {"agnocast_beside_63_busy_topics", {small}},
      {"agnocast_constant_bytes", size_labels},
      {"iceoryx_constant_bytes", size_labels},
      {"unix_socket_constant_bytes", size_labels},
      {"python_subscriber_constant_bytes", {smallest_label, largest_label}},
      {"agnocast_fanout", fanout_labels},
      {"mqueue_fanout", fanout_labels},
      {"agnocast_service", service_labels},
      {"agnocast_ping_pong", {small}},
      {"unix_socket_request_response", {"1 B"}},
      {"agnocast_beside_idle_topics", topics_labels},
      {"agnocast_with_processes_attached", processes_labels},
      {"agnocast_depth", depth_labels},
      {"agnocast_publish_taken", depth_labels},
      {"agnocast_publish_into_full_queue", depth_labels},
      {"agnocast_publish_into_full_queues", full_queues_labels},
      {"agnocast_beside_other_publishers", publishers_labels},
      {"agnocast_longest_topic_name", {small}},
  };
  for (const auto& [who, labels] : series) {
    for (const auto& label : labels) {
      if (!samples.has(who, label)) continue;
      json stats = stats_json(samples.pooled(who, label));
      if (plan.icount) {
        // Each round's p50: in this mode they agree, and the report shows it.
        json by_round = json::array();
        for (std::size_t round = 0; round < samples.rounds(who, label); ++round) {
          by_round.push_back(samples.round_p50(round, who, label));
        }
        stats["p50_us_by_round"] = by_round;
      }
      report["latency"][who][label] = stats;
    }
  }
  if (want_iceoryx && !iceoryx) {
    report["latency"]["iceoryx"] = nullptr;
    report["latency"]["iceoryx_constant_bytes"] = nullptr;
  }
  if (want_python && !python) report["latency"]["python_subscriber_constant_bytes"] = nullptr;
  std::remove(windows_path.c_str());
  for (const auto& [who, labels] : send_calls) {
    for (const auto& [label, calls] : labels) {
      if (calls.send_us.empty()) continue;
      report["send_call"][who][label] = {{"samples", calls.send_us.size()},
                                         {"p50_us", bench::median(calls.send_us)},
                                         {"delivered_before_it_returned", calls.delivered_first}};
      if (!calls.send_cpu_us.empty()) {
        report["send_call"][who][label]["cpu_p50_us"] = bench::median(calls.send_cpu_us);
      }
    }
  }
  report["failed_cells"] = failed_cells;
  if (!plan.icount) {
    report["background"] = {
        {"topics", plan.background_topics},
        {"offered_per_s", plan.background_topics * 1e9 / bench::steady_period_ns},
        {"delivered_per_s", bench::median(background_rates)}};
  }

  auto p50 = [&](std::size_t round, const char* who, const std::string& label) {
    return samples.round_p50(round, who, label);
  };
  const std::string largest = bench::format_size(plan.sizes.back());
  const std::string smallest = bench::format_size(plan.sizes.front());
  const std::string largest_service = bench::format_size(plan.service_sizes.back());
  auto slope = [&](std::size_t round, const char* who) {
    const double first = static_cast<double>(plan.fanouts.front());
    const double last = static_cast<double>(plan.fanouts.back());
    return (p50(round, who, std::to_string(plan.fanouts.back())) -
            p50(round, who, std::to_string(plan.fanouts.front()))) /
           (last - first);
  };
  const std::vector<RoundRatio> ratios{
      {"size_flatness", 1.05, 1.01,
       [&](std::size_t r) {
         return p50(r, "agnocast_constant_bytes", largest) /
                p50(r, "agnocast_constant_bytes", smallest);
       }},
      {"python_size_flatness", 1.05, 1.01,
       [&](std::size_t r) {
         return p50(r, "python_subscriber_constant_bytes", largest) /
                p50(r, "python_subscriber_constant_bytes", smallest);
       }},
      {"size_flatness_iceoryx", 1.05, 1.01,
       [&](std::size_t r) {
         return p50(r, "iceoryx_constant_bytes", largest) /
                p50(r, "iceoryx_constant_bytes", smallest);
       }},
      {"vs_iceoryx", 1.0, 0.85,
       [&](std::size_t r) { return p50(r, "agnocast", page) / p50(r, "iceoryx", page); }},
      {"vs_iceoryx_64", 1.0, 0.85,
       [&](std::size_t r) { return p50(r, "agnocast", small) / p50(r, "iceoryx", small); }},
      {"vs_iceoryx_constant_bytes", 1.0, not_in_mode,
       [&](std::size_t r) {
         return p50(r, "agnocast_constant_bytes", smallest) /
                p50(r, "iceoryx_constant_bytes", smallest);
       }},
      {"vs_mqueue_floor", 1.3, 1.3,
       [&](std::size_t r) { return p50(r, "agnocast", small) / p50(r, "mqueue_floor", "1 B"); }},
      {"vs_epoll_floor", 1.3, 1.5,
       [&](std::size_t r) {
         return p50(r, "agnocast", small) / p50(r, "mqueue_epoll_floor", "1 B");
       }},
      {"topics_64", 1.2, not_in_mode,
       [&](std::size_t r) {
         return p50(r, "agnocast_beside_63_busy_topics", small) / p50(r, "agnocast", small);
       }},
      {"fanout_slope", 1.2, 1.2,
       [&](std::size_t r) { return slope(r, "agnocast_fanout") / slope(r, "mqueue_fanout"); }},
      {"fanout_64", 64.0, 64.0,
       [&](std::size_t r) {
         return p50(r, "agnocast_fanout", std::to_string(plan.fanouts.back())) /
                p50(r, "agnocast_fanout", std::to_string(plan.fanouts.front()));
       }},
      {"service_vs_one_way", 2.2, 2.2,
       [&](std::size_t r) {
         return p50(r, "agnocast_service", small) / p50(r, "agnocast", small);
       }},
      {"idle_topics_flatness", not_in_mode, 1.02,
       [&](std::size_t r) {
         return p50(r, "agnocast_beside_idle_topics", std::to_string(plan.idle_topics.back())) /
                p50(r, "agnocast_beside_idle_topics", std::to_string(plan.idle_topics.front()));
       }},
      {"attached_processes_flatness", not_in_mode, 1.02,
       [&](std::size_t r) {
         return p50(r, "agnocast_with_processes_attached",
                    std::to_string(plan.attached_processes.back())) /
                p50(r, "agnocast_with_processes_attached",
                    std::to_string(plan.attached_processes.front()));
       }},
      {"depth_flatness", not_in_mode, 1.02,
       [&](std::size_t r) {
         return p50(r, "agnocast_depth", std::to_string(plan.depths.back())) /
                p50(r, "agnocast_depth", std::to_string(plan.depths.front()));
       }},
      {"full_queue_depth_flatness", not_in_mode, 1.02,
       [&](std::size_t r) {
         return p50(r, "agnocast_publish_into_full_queue", std::to_string(plan.depths.back())) /
                p50(r, "agnocast_publish_into_full_queue", std::to_string(plan.depths.front()));
       }},
      {"other_publishers_flatness", not_in_mode, 1.02,
       [&](std::size_t r) {
         return p50(r, "agnocast_beside_other_publishers",
                    std::to_string(plan.other_publishers.back())) /
                p50(r, "agnocast_beside_other_publishers",
                    std::to_string(plan.other_publishers.front()));
       }},
      {"longest_topic_name", not_in_mode, 1.02,
       [&](std::size_t r) {
         return p50(r, "agnocast_longest_topic_name", small) / p50(r, "agnocast", small);
       }},
      {"service_size_flatness", 1.02, 1.02,
       [&](std::size_t r) {
         // A smoke run measures the smallest size only.
         if (plan.service_sizes.size() < 2) return std::numeric_limits<double>::quiet_NaN();
         return p50(r, "agnocast_service", largest_service) / p50(r, "agnocast_service", small);
       }},
  };
  for (const RoundRatio& ratio : ratios) {
    if (plan.icount) {
      // Deterministic: one value, from the pooled p50s.
      if (std::isnan(ratio.icount_target)) continue;
      const double value = ratio.of_round(all_rounds);
      report["ratios"][ratio.name] = std::isfinite(value) ? json(value) : json();
      report["met"][ratio.name] =
          std::isfinite(value) ? json(value <= ratio.icount_target) : json();
      report["targets"][ratio.name] = ratio.icount_target;
      continue;
    }
    if (std::isnan(ratio.target)) continue;
    std::vector<double> per_round;
    for (std::size_t round = 0; round < plan.rounds; ++round) {
      per_round.push_back(ratio.of_round(round));
    }
    const bench::RoundEstimate estimate = bench::estimate_over_rounds(per_round);
    if (estimate.rounds == 0) {
      report["ratios"][ratio.name] = nullptr;
      report["ratio_ci"][ratio.name] = nullptr;
      report["met"][ratio.name] = nullptr;
    } else {
      report["ratios"][ratio.name] = estimate.value;
      report["ratio_ci"][ratio.name] = {estimate.low, estimate.high};
      report["met"][ratio.name] = estimate.high <= ratio.target;
    }
    report["targets"][ratio.name] = ratio.target;
    report["ratio_rounds"][ratio.name] = estimate.rounds;
  }
  // The publisher's own time in its publish() call (its thread's CPU time:
  // on one vCPU the subscribers it wakes may run inside the call) against
  // the subscribers it wakes: a least-squares line through the fan-out
  // points' p50s.
  if (report.contains("send_call") && report["send_call"].contains("agnocast_fanout")) {
    double n = 0, sum_x = 0, sum_y = 0, sum_xx = 0, sum_xy = 0;
    for (std::size_t subscribers : plan.fanouts) {
      const json& call = report["send_call"]["agnocast_fanout"][std::to_string(subscribers)];
      if (!call.is_object() || !call.contains("cpu_p50_us")) continue;
      const double x = static_cast<double>(subscribers), y = call["cpu_p50_us"].get<double>();
      n += 1;
      sum_x += x;
      sum_y += y;
      sum_xx += x * x;
      sum_xy += x * y;
    }
    if (n >= 2 && n * sum_xx != sum_x * sum_x) {
      const double per_subscriber = (n * sum_xy - sum_x * sum_y) / (n * sum_xx - sum_x * sum_x);
      report["publish_call_us"] = {{"base", (sum_y - per_subscriber * sum_x) / n},
                                   {"per_subscriber", per_subscriber}};
    }
  }
  std::vector<double> agnocast_slopes, mqueue_slopes;
  for (std::size_t round = 0; round < plan.rounds; ++round) {
    agnocast_slopes.push_back(slope(round, "agnocast_fanout"));
    mqueue_slopes.push_back(slope(round, "mqueue_fanout"));
  }
  report["fanout_slope_us_per_subscriber"] =
      plan.icount ? json{{"agnocast", slope(all_rounds, "agnocast_fanout")},
                         {"mqueue", slope(all_rounds, "mqueue_fanout")}}
                  : json{{"agnocast", bench::median(agnocast_slopes)},
                         {"mqueue", bench::median(mqueue_slopes)}};

  json breakdown;
  if (plan.selected("cost_breakdown")) {
    std::cerr << "the cost of one message, call by call...\n";
    breakdown = cost_breakdown(breakdown_program, plan.smoke);
  }
  if (breakdown.is_object()) {
    // The bare hop, measured above in the same boot: mq_send to the
    // receiver's return from mq_receive, receiver asleep in epoll_wait
    // (agnocast's executor) or in mq_receive.
    breakdown["reference"]["mqueue_hop_epoll_ns"] =
        samples.round_p50(all_rounds, "mqueue_epoll_floor", "1 B") * 1000;
    breakdown["reference"]["mqueue_hop_ns"] =
        samples.round_p50(all_rounds, "mqueue_floor", "1 B") * 1000;
  }
  report["cost_breakdown"] = breakdown;
  if (plan.selected("cost_breakdown_service")) {
    std::cerr << "the cost of one round trip of a service, call by call...\n";
    report["cost_breakdown_service"] = cost_breakdown(breakdown_program, plan.smoke, " --service");
  }
  if ((plan.icount || plan.smoke) && plan.selected("kernel_memory")) {
    std::cerr << "kernel memory per object...\n";
    try {
      report["kernel_memory"] = bench::measure_kernel_memory(plan.memory_objects);
    } catch (const std::exception& error) {
      // The rest of the report stands; the smoke's shape check fails on it.
      std::cerr << "agnocast-bench: kernel memory: " << error.what() << "\n";
      report["kernel_memory"] = {{"error", error.what()}};
    }
  }
  if (!plan.series.empty()) return report;  // a selection: its series only

  std::cerr << "system calls and CPU time at 1 kHz...\n";
  // CPU time without counters, as iceoryx's and the floor's; then the counts.
  const bench::SteadyResult uncounted =
      bench::run_agnocast_steady(10, plan.steady_messages, 1, false);
  const bench::SteadyResult qos_10 = bench::run_agnocast_steady(10, plan.steady_messages, 1, true);
  const bench::SteadyResult qos_1 = bench::run_agnocast_steady(1, plan.steady_messages, 1, true);
  const bench::SteadyResult qos_10_fanout_4 =
      bench::run_agnocast_steady(10, plan.steady_messages, 4, true);
  report["syscalls_per_message"] = {{"qos_10", syscalls_json(qos_10)},
                                    {"qos_1", syscalls_json(qos_1)},
                                    {"qos_10_4_subscribers", syscalls_json(qos_10_fanout_4)}};
  report["allocations_per_message"] = {{"publisher", uncounted.publisher_allocations},
                                       {"subscriber", uncounted.subscriber_allocations}};
  report["cpu_us_per_message"] = {
      {"agnocast", cpu_json(uncounted.cpu)},
      {"iceoryx", iceoryx ? cpu_json(iceoryx->cpu_per_message(plan.steady_messages)) : json()},
      {"mqueue_epoll_floor", cpu_json(bench::run_mqueue_floor_cpu(plan.steady_messages))}};

  std::cerr << "throughput...\n";
  report["throughput"] = throughput_json(plan, iceoryx ? &*iceoryx : nullptr);

  // Recording is CPU time and drops at a real rate: wall-time work, so only
  // in the ordinary mode.
  if (!plan.icount) {
    std::cerr << "recording with agnocast-cli bag record...\n";
    try {
      report["recording"] = bench::run_recording(cli, plan.smoke);
    } catch (const std::exception& error) {
      // The rest of the report stands; the smoke's shape check fails on it.
      std::cerr << "agnocast-bench: recording: " << error.what() << "\n";
      report["recording"] = {{"error", error.what()}};
    }
  }
  return report;
}

// Measures agnocast's 64 B series twice in a row and compares the p50s: in
// icount mode they agree (within `tolerance`), whatever the host does.
int repeat_check(std::size_t samples, double tolerance) {
  std::vector<double> p50s;
  for (int run = 0; run < 2; ++run) {
    const Cell cell{"agnocast", "64 B",
                    [&](auto&) { return bench::run_agnocast_latency(64, samples, 1).front(); }};
    std::vector<std::int64_t> measured, extra;
    if (!run_isolated(cell, 300, measured, extra)) return 1;
    p50s.push_back(bench::summarize(measured).p50_us * 1000);
  }
  const double difference = std::abs(p50s[1] - p50s[0]) / std::min(p50s[0], p50s[1]);
  std::printf("agnocast 64 B p50: %.0f ns, then %.0f ns: %.3f %% apart (at most %.1f %%)\n",
              p50s[0], p50s[1], difference * 100, tolerance * 100);
  return difference <= tolerance ? 0 : 1;
}

// Nothing on the message path grows with what else is registered: agnocast's
// 64 B p50 beside 1 and 1,000 idle topics, and with 2 and 50 processes
// attached, each pair within `tolerance`. In icount mode the p50s are
// instruction counts, so this checks the scale series' slope, not a timing.
int scale_check(std::size_t samples, double tolerance) {
  auto p50_of = [&](const std::function<std::vector<std::int64_t>()>& measure) {
    const Cell cell{"agnocast", "64 B", [&](auto&) { return measure(); }};
    std::vector<std::int64_t> measured, extra;
    if (!run_isolated(cell, 300, measured, extra)) return std::numeric_limits<double>::quiet_NaN();
    return bench::summarize(measured).p50_us * 1000;
  };
  auto p50_beside = [&](std::size_t processes, std::size_t topics) {
    return p50_of([=] {
      const bench::IdleEndpoints idle(processes, topics);
      return bench::run_agnocast_latency(64, samples, 1).front();
    });
  };
  auto p50_at_depth = [&](std::size_t depth) {
    return p50_of(
        [=] { return bench::run_agnocast_latency(64, samples, 1, {.depth = depth}).front(); });
  };
  auto full_queue_publish_at_depth = [&](std::size_t depth) {
    return p50_of([=] { return bench::run_agnocast_publish_call(depth, 1, samples, true); });
  };
  struct Pair {
    const char* what;
    double small, large;
  };
  const Pair pairs[] = {
      {"one way 64 B, 1 -> 1,000 idle topics", p50_beside(1, 1), p50_beside(1, 1000)},
      {"one way 64 B, 2 -> 50 processes attached", p50_beside(0, 0), p50_beside(48, 48)},
      {"one way 64 B, QoS depth 1 -> 1,024", p50_at_depth(1),
       p50_at_depth(agnocast::qos_depth_max)},
      {"publish() into a full queue, depth 1 -> 1,024", full_queue_publish_at_depth(1),
       full_queue_publish_at_depth(agnocast::qos_depth_max)},
  };
  int status = 0;
  for (const Pair& pair : pairs) {
    const double growth = pair.large / pair.small - 1;
    const bool flat = std::isfinite(growth) && std::abs(growth) <= tolerance;
    std::printf("agnocast p50, %s: %.0f ns, then %.0f ns: %+.3f %% (at most %.1f %%): %s\n",
                pair.what, pair.small, pair.large, growth * 100, tolerance * 100,
                flat ? "flat" : "NOT FLAT");
    if (!flat) status = 1;
  }
  return status;
}

// The 64 B series of agnocast, iceoryx, the mqueue floors and the Unix socket,
// with and without 64 MiB written before each sample, in shuffled order over
// `plan.rounds` rounds.  Per series: the one-way latency, how long the
// sender's send call took (publish(), mq_send, write), how often the receiver
// had the message before that call returned, and with `counters` the kernel's
// counters over each sample (the reads cost time of their own, so the
// latencies are then a little longer).
int window_check(const Plan& plan, const std::string& iceoryx_role, bool counters) {
  setenv("AGNOCAST_BENCH_WINDOWS", counters ? "counters" : "times", 1);
  const std::string path = "/tmp/agnocast-bench-windows-" + std::to_string(getpid());
  setenv("AGNOCAST_BENCH_WINDOWS_FILE", path.c_str(), 1);
  auto iceoryx = bench::IceoryxRunner::start(iceoryx_role);
  const std::size_t m = plan.constant_bytes_samples;
  const std::size_t scratch = bench::constant_written_bytes - 64;
  std::mt19937_64 shuffle(plan.seed);
  struct Series {
    std::vector<double> latency_us, send_us;
    std::size_t before_return = 0;
    std::map<std::string, std::vector<double>> counted;
  };
  std::map<std::string, Series> all;
  for (std::size_t round = 0; round < plan.rounds; ++round) {
    std::vector<Cell> cells;
    for (std::size_t written : {std::size_t{0}, scratch}) {
      const std::string label = written ? "64 MiB written" : "nothing written";
      cells.push_back(
          {"agnocast", label, [=](auto&) {
             return bench::run_agnocast_latency(64, m, 1, {.scratch_bytes = written}).front();
           }});
      if (iceoryx) {
        cells.push_back(
            {"iceoryx", label, [&, written](auto&) { return iceoryx->measure(64, m, written); }});
      }
      cells.push_back({"mqueue, receiver in mq_receive", label, [=](auto&) {
                         return bench::run_mqueue_floor(m, bench::FloorWait::blocking, written);
                       }});
      cells.push_back({"mqueue, receiver in epoll_wait", label, [=](auto&) {
                         return bench::run_mqueue_floor(m, bench::FloorWait::epoll, written);
                       }});
      cells.push_back({"Unix socket", label,
                       [=](auto&) { return bench::run_unix_socket_copy(64, m, written); }});
    }
    std::shuffle(cells.begin(), cells.end(), shuffle);
    std::cerr << "round " << round + 1 << " of " << plan.rounds << "\n";
    for (const Cell& cell : cells) {
      std::remove(path.c_str());
      std::vector<std::int64_t> measured, extra;
      if (!run_isolated(cell, 180, measured, extra)) continue;
      const auto windows = read_windows(path);
      if (windows.size() < measured.size()) continue;
      Series& series = all[cell.who + ", " + cell.label];
      for (std::size_t i = 0; i < measured.size(); ++i) {
        const auto& window = windows[windows.size() - measured.size() + i];
        const double send_us = static_cast<double>(window.at("send_ns")) / 1000;
        const double latency_us = static_cast<double>(measured[i]) / 1000;
        series.latency_us.push_back(latency_us);
        series.send_us.push_back(send_us);
        std::cerr << "sample " << cell.who << ", " << cell.label << ": latency_ns=" << measured[i];
        for (const auto& [name, value] : window) std::cerr << " " << name << "=" << value;
        std::cerr << "\n";
        if (latency_us < send_us) ++series.before_return;
        for (const auto& [name, value] : window) {
          if (name != "seq" && name != "cpu" && name != "send_ns" && name != "acked_ns" &&
              name != "size" && name != "scratch") {
            series.counted[name].push_back(static_cast<double>(value));
          }
        }
      }
    }
  }
  std::remove(path.c_str());
  std::printf(
      "| 64 B, one way | samples | latency p50, us | send call p50, us | delivered before the "
      "send call returned |\n|---|---|---|---|---|\n");
  for (const auto& [name, series] : all) {
    std::printf("| %s | %zu | %.0f | %.0f | %zu of %zu |\n", name.c_str(), series.latency_us.size(),
                bench::median(series.latency_us), bench::median(series.send_us),
                series.before_return, series.latency_us.size());
  }
  if (!counters || all.empty()) return 0;
  std::printf(
      "\nKernel counters over a sample (every CPU, from before the send to the ack), "
      "median of samples:\n\n| series |");
  const auto& names = all.begin()->second.counted;
  for (const auto& [name, values] : names) std::printf(" %s |", name.c_str());
  std::printf("\n|---|");
  for (std::size_t i = 0; i < names.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const auto& [name, series] : all) {
    std::printf("| %s |", name.c_str());
    for (const auto& [counter, values] : series.counted) {
      std::printf(" %.1f |", bench::median(values));
    }
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "agnocast-bench: latency, fan-out, system calls and CPU time against iceoryx and "
      "baselines"};
  bool json_output = false, smoke = false;
  const std::filesystem::path here = std::filesystem::read_symlink("/proc/self/exe").parent_path();
  std::string iceoryx_role = (here / "agnocast-bench-iceoryx").string();
  std::string breakdown_program = (here / "agnocast-bench-breakdown").string();
  std::string cli = (here / "agnocast-cli").string();
  bench::PythonSubscriber python{AGNOCAST_BENCH_PYTHON, (here / "python_subscriber.py").string(),
                                 AGNOCAST_BENCH_PYTHON_PATH};
  Plan plan;
  app.add_flag("--json", json_output, "print one JSON object instead of Markdown tables");
  app.add_flag("--smoke", smoke,
               "tiny counts, then check the report's shape: every measurement works");
  auto* rounds = app.add_option("--rounds", plan.rounds,
                                "rounds (at least 20 for the report's intervals; with --icount "
                                "3 by default)")
                     ->check(CLI::Range(2, 1000));
  app.add_option("--seed", plan.seed, "seed of the rounds' shuffled order");
  app.add_option("--iceoryx-role", iceoryx_role, "the iceoryx role program");
  app.add_option("--breakdown-program", breakdown_program, "the cost breakdown program");
  app.add_option("--cli", cli, "the agnocast-cli program, whose bag record is measured");
  app.add_option("--python", python.interpreter, "the Python interpreter of the Python series");
  app.add_option("--python-path", python.package_path,
                 "the folder holding the agnocast Python package (PYTHONPATH)");
  app.add_option("--series", plan.series,
                 "run only the latency series whose names match this regular expression (e.g. "
                 "python_subscriber), and nothing else of the report");
  app.add_flag("--icount", plan.icount,
               "the VM runs in QEMU's instruction-counting mode: fewer rounds, single-valued "
               "ratios, no series that needs parallel cores");
  app.add_option("--host-cpu", plan.host_cpu, "the host's CPU, for the report");
  app.add_option("--qemu-version", plan.qemu_version, "QEMU's version, for the report");
  app.add_option("--qemu-flags", plan.qemu_flags, "QEMU's accelerator flags, for the report");
  bool repeat = false;
  app.add_flag("--repeat-check", repeat,
               "measure agnocast's 64 B p50 twice; fail if they differ by more than 1 % (a check "
               "of icount mode's repeatability)");
  bool scale = false;
  app.add_flag("--scale-check", scale,
               "measure agnocast's 64 B p50 beside 1 and 1,000 idle topics, with 2 and 50 "
               "processes attached, at QoS depth 1 and 1,024, and publish() into a full queue "
               "at depth 1 and 1,024; fail if a pair differs by more than 2 % (in icount mode: "
               "nothing on the message path grows with them)");
  bool windows = false, window_counters = false;
  app.add_flag("--window-counters", window_counters,
               "with --window-check: the kernel's counters too, which cost time themselves");
  app.add_flag("--window-check", windows,
               "measure only the 64 B series of agnocast, iceoryx, the mqueue floors and the Unix "
               "socket, with and without 64 MiB written first: latency, the sender's send call, "
               "and whether the receiver had the message before that call returned");
  std::string render;
  app.add_option("--render", render,
                 "measure nothing: print a saved --json report as Markdown tables");
  std::string readme;
  auto* readme_option =
      app.add_option("--readme", readme,
                     "measure nothing: print benchmarks/README.md from a report of both modes");
  std::string plots;
  app.add_option("--plots", plots,
                 "with --readme: write the README's plots (SVG) into this folder and link them "
                 "as FOLDER-NAME/PLOT.svg, for a README beside the folder")
      ->needs(readme_option);
  CLI11_PARSE(app, argc, argv);

  if (!readme.empty()) {
    std::ifstream saved(readme);
    try {
      const json combined = json::parse(saved);
      std::map<std::string, bench::PlotLinks> links;
      if (!plots.empty()) links = bench::write_readme_plots(combined, plots);
      bench::print_readme(combined, links);
    } catch (const std::exception& error) {
      std::cerr << "agnocast-bench: " << readme << ": " << error.what() << "\n";
      return 1;
    }
    return 0;
  }
  if (!render.empty()) {
    std::ifstream saved(render);
    try {
      bench::print_markdown(json::parse(saved));
    } catch (const std::exception& error) {
      std::cerr << "agnocast-bench: " << render << ": " << error.what() << "\n";
      return 1;
    }
    return 0;
  }

  // In icount mode the address layout is fixed (no ASLR, like setarch -R):
  // where a buffer falls within its page changes how many pages the kernel
  // checks, so a randomized layout moved a p50 by ~4 % from boot to boot.
  // The roles are forked or started from here and inherit it.
  const int persona = personality(0xffffffff);
  if (plan.icount && persona != -1 && (persona & ADDR_NO_RANDOMIZE) == 0 &&
      personality(static_cast<unsigned long>(persona) | ADDR_NO_RANDOMIZE) != -1) {
    execv("/proc/self/exe", argv);
    std::cerr << "agnocast-bench: could not start again without address randomization\n";
  }
  if (repeat) return repeat_check(plan.latency_samples, 0.01);
  if (scale) return scale_check(plan.latency_samples, 0.02);
  if (windows) return window_check(plan, iceoryx_role, window_counters);
  if (smoke) plan.make_smoke();
  if (plan.icount && !smoke && rounds->count() == 0) plan.rounds = 3;
  if (plan.icount && !smoke) plan.throughput_repeats = 1;  // deterministic
  if (plan.icount && !smoke) plan.fanouts = plan.icount_fanouts;
  try {
    json report = run(plan, iceoryx_role, breakdown_program, cli, python);
    // A smoke run's findings come before the report, where a log's reader
    // sees them first.
    std::vector<std::string> errors;
    if (smoke) errors = bench::report_shape_errors(report);
    for (const auto& error : errors) std::cerr << "agnocast-bench: report: " << error << "\n";
    std::cerr.flush();
    if (json_output) {
      std::cout << report.dump() << "\n";
    } else {
      bench::print_markdown(report);
    }
    if (!errors.empty()) return 1;
  } catch (const std::exception& error) {
    std::cerr << "agnocast-bench: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
