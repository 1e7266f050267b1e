#include "report_shape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

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
  // A side's calls per message: each of calls made, and call `bounded`
  // within [least, most] per message.
  void syscalls(const std::string& run, const std::string& side,
                const std::vector<std::string>& calls, const std::string& bounded, double least,
                double most) {
    for (const auto& call : calls) positive({"syscalls_per_message", run, side + "_by_call", call});
    const std::vector<std::string> path{"syscalls_per_message", run, side + "_by_call", bounded};
    const json* value = at(path);
    if (value && value->is_number() &&
        (value->get<double>() < least || value->get<double>() > most)) {
      errors.push_back(join(path) + " is " + std::to_string(value->get<double>()) +
                       " per message, outside [" + std::to_string(least) + ", " +
                       std::to_string(most) + "]");
    }
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

// The value at path, or null when any key is missing.
const json& at_path(const json& root, std::initializer_list<const char*> path) {
  static const json null_value;
  const json* node = &root;
  for (const char* key : path) {
    if (!node->is_object() || !node->contains(key)) return null_value;
    node = &(*node)[key];
  }
  return *node;
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

void print_breakdown(const json& breakdown) {
  if (!breakdown.is_object()) return;
  std::printf(
      "\nCost of one 64 B message, call by call (%s messages one at a time, QoS 10; latency p50 "
      "in this run %s ns):\n\n| side | call | per message | ns each (p50) |\n|---|---|---|---|\n",
      number(breakdown["messages"], "%.0f").c_str(),
      number(breakdown["latency_ns"], "%.0f").c_str());
  for (const char* side : {"publisher", "subscriber"}) {
    const json& costs = breakdown[side];
    for (const json& call : costs["calls"]) {
      std::printf("| %s | `%s` | %s | %s |\n", side, call["name"].get<std::string>().c_str(),
                  number(call["per_message"], "%.2f").c_str(), number(call["ns"], "%.0f").c_str());
    }
    std::printf("| %s | library, user space | 1 | %s |\n", side,
                number(costs["library_ns"], "%.0f").c_str());
    if (costs.contains("blocking_wait")) {
      std::printf("| %s | %s | | |\n", side, costs["blocking_wait"].get<std::string>().c_str());
    }
  }
  std::printf(
      "\nPublisher's last `mq_send` to the subscriber's return from `epoll_wait`: %s ns; from "
      "there to the callback: %s ns; from the callback's end to the next wait: %s ns.\n",
      number(breakdown["handoff_ns"], "%.0f").c_str(),
      number(breakdown["wake_to_callback_ns"], "%.0f").c_str(),
      number(breakdown["after_callback_ns"], "%.0f").c_str());
  const json& reference = breakdown["reference"];
  std::printf(
      "\n| reference, same boot, ns (p50) | null ioctl (`GET_VERSION`) | `getppid()` | `mq_send` | "
      "`mq_receive` | `epoll_wait`, ready | mqueue hop, receiver in `epoll_wait` | mqueue hop, "
      "receiver in `mq_receive` | clock read |\n|---|---|---|---|---|---|---|---|---|\n"
      "| | %s | %s | %s | %s | %s | %s | %s | %s |\n",
      number(reference["null_ioctl_ns"], "%.0f").c_str(),
      number(reference["getppid_ns"], "%.0f").c_str(),
      number(reference["mq_send_ns"], "%.0f").c_str(),
      number(reference["mq_receive_ns"], "%.0f").c_str(),
      number(reference["epoll_wait_ready_ns"], "%.0f").c_str(),
      number(reference["mqueue_hop_epoll_ns"], "%.0f").c_str(),
      number(reference["mqueue_hop_ns"], "%.0f").c_str(),
      number(reference["clock_read_ns"], "%.0f").c_str());
  if (!breakdown["timeline"].empty()) {
    std::printf(
        "\nThe message of median latency on one timeline (ns from the publish() call):\n\n"
        "| side | what | start | end |\n|---|---|---|---|\n");
    for (const json& span : breakdown["timeline"]) {
      std::printf("| %s | %s | %s | %s |\n", span["side"].get<std::string>().c_str(),
                  span["what"].get<std::string>().c_str(), number(span["start_ns"], "%.0f").c_str(),
                  number(span["end_ns"], "%.0f").c_str());
    }
  }
}

// A service's round trip, call by call: what each side runs in its window.
void print_service_breakdown(const json& breakdown) {
  if (!breakdown.is_object()) return;
  std::printf(
      "\nCost of one 64 B request → response round trip of a service, call by call (%s round "
      "trips one at a time; round trip p50 in this run %s ns), calls and user space within the "
      "window only:\n\n| side | call | per round trip | ns each (p50) |\n|---|---|---|---|\n",
      number(breakdown["messages"], "%.0f").c_str(),
      number(breakdown["round_trip_ns"], "%.0f").c_str());
  for (const char* side : {"client", "server"}) {
    const json& costs = breakdown[side];
    for (const json& call : costs["calls"]) {
      std::printf("| %s | `%s` | %s | %s |\n", side, call["name"].get<std::string>().c_str(),
                  number(call["per_message"], "%.2f").c_str(), number(call["ns"], "%.0f").c_str());
    }
    std::printf("| %s | library, user space | 1 | %s |\n", side,
                number(costs["library_ns"], "%.0f").c_str());
  }
  std::printf(
      "\nLeft of the window, neither side in user space nor in a timed call (the two wake-ups' "
      "context switches): %s ns.\n",
      number(breakdown["switches_ns"], "%.0f").c_str());
  if (!breakdown["timeline"].empty()) {
    std::printf(
        "\nThe round trip of median time on one timeline (ns from the "
        "`async_send_request()` call):\n\n| side | what | start | end |\n|---|---|---|---|\n");
    for (const json& span : breakdown["timeline"]) {
      std::printf("| %s | %s | %s | %s |\n", span["side"].get<std::string>().c_str(),
                  span["what"].get<std::string>().c_str(), number(span["start_ns"], "%.0f").c_str(),
                  number(span["end_ns"], "%.0f").c_str());
    }
  }
}

// The plot of the table just printed, when the README has one.
void print_plot(const PlotLinks& plots, const char* table) {
  const auto link = plots.find(table);
  if (link != plots.end()) std::printf("\n%s\n", link->second.c_str());
}

// Each limit of <agnocast/limits.hpp> on the message path, reached, beside
// the same measurement far from it; icount mode only.
void print_limits(const json& report, const char* unit) {
  const json& latency = report["latency"];
  for (const char* who : {"agnocast_depth", "agnocast_publish_into_full_queues",
                          "agnocast_beside_other_publishers", "agnocast_longest_topic_name"}) {
    if (!latency.contains(who) || !latency[who].is_object() || latency[who].empty()) return;
  }
  auto first_label = [&](const char* who) { return latency[who].begin().key(); };
  auto last_label = [&](const char* who) {
    std::string last;
    for (const auto& [label, stats] : latency[who].items()) last = label;
    return last;
  };
  std::printf(
      "\n| limit reached, %s (p50 / p99) | measured | at the limit | far from it |\n"
      "|---|---|---|---|\n",
      unit);
  const std::string depth_max = last_label("agnocast_depth");
  const std::string depth_min = first_label("agnocast_depth");
  std::printf(
      "| `qos_depth_max` = %s | `publish()` into a full queue | %s | %s (depth %s) |\n",
      depth_max.c_str(), cell(latency, "agnocast_publish_into_full_queue", depth_max).c_str(),
      cell(latency, "agnocast_publish_into_full_queue", depth_min).c_str(), depth_min.c_str());
  const std::string most = last_label("agnocast_publish_into_full_queues");
  const std::string fewest = first_label("agnocast_publish_into_full_queues");
  std::printf(
      "| `subscribers_per_topic_max` = %s | `publish()` into that many full depth-1 queues of "
      "polling subscribers | %s | %s (%s) |\n",
      most.c_str(), cell(latency, "agnocast_publish_into_full_queues", most).c_str(),
      cell(latency, "agnocast_publish_into_full_queues", fewest).c_str(), fewest.c_str());
  const std::string others = last_label("agnocast_beside_other_publishers");
  std::printf(
      "| `publishers_per_topic_max` = %d | one-way 64 B beside %s other publishers of the topic "
      "| %s | %s (none) |\n",
      std::stoi(others) + 1, others.c_str(),
      cell(latency, "agnocast_beside_other_publishers", others).c_str(),
      cell(latency, "agnocast_beside_other_publishers",
           first_label("agnocast_beside_other_publishers"))
          .c_str());
  std::printf(
      "| `topic_name_max` = 245 | one-way 64 B on a topic name that long | %s | %s "
      "(`agnocast`, 64 B) |\n",
      cell(latency, "agnocast_longest_topic_name", "64 B").c_str(),
      cell(latency, "agnocast", "64 B").c_str());
  if (latency.contains("agnocast_beside_idle_topics")) {
    const std::string topics = last_label("agnocast_beside_idle_topics");
    const std::string fewest_topics = first_label("agnocast_beside_idle_topics");
    std::printf(
        "| the module's `max_topics_per_namespace` (4,096 by default; 16,384 here) | one-way 64 "
        "B beside %s idle topics | %s | %s (%s) |\n",
        topics.c_str(), cell(latency, "agnocast_beside_idle_topics", topics).c_str(),
        cell(latency, "agnocast_beside_idle_topics", fewest_topics).c_str(), fewest_topics.c_str());
  }
}

// Kernel memory per object the module keeps, from the memory cgroup's
// counters; icount mode (and the smoke run).
void print_kernel_memory(const json& report) {
  const json& memory = at_path(report, {"kernel_memory", "bytes_per_object"});
  if (!memory.is_object()) return;
  std::printf(
      "\n| kernel memory per object, bytes (%s of each, made in a memory cgroup of their own) | "
      "`slab` of memory.stat | `kernel` of memory.stat |\n|---|---|---|\n",
      number(report["kernel_memory"]["objects"], "%.0f").c_str());
  const std::pair<const char*, const char*> kinds[] = {
      {"topic_with_publisher", "a topic with its first publisher"},
      {"publisher", "another publisher of a topic"},
      {"polling_subscriber", "a polling subscriber, depth 1"},
      {"callback_subscriber", "a callback subscriber, depth 10, with its notification queue"},
      {"held_entry", "an entry a publisher's depth window keeps"}};
  for (const auto& [kind, what] : kinds) {
    std::printf("| %s | %s | %s |\n", what, number(at_path(memory, {kind, "slab"}), "%.0f").c_str(),
                number(at_path(memory, {kind, "kernel"}), "%.0f").c_str());
  }
}

// Messages back to back, agnocast against iceoryx.
void print_throughput(const json& report) {
  const json& throughput = report["throughput"];
  if (!throughput.contains("agnocast")) return;  // reports from before it had sizes
  const bool icount = report.value("mode", "ordinary") == "icount";
  auto rate = [](const json& run) {
    if (!run.is_object()) return std::string("—");
    std::string text = number(run["value"], "%.0f");
    if (run["interval"].is_array()) {
      text += " (" + number(run["interval"][0], "%.0f") + "–" + number(run["interval"][1], "%.0f") +
              ")";
    }
    return text + ", " + number(json(run["received_fraction"].get<double>() * 100), "%.0f") +
           " % received";
  };
  std::printf(
      "\n| back to back, one publisher → one subscriber, messages per %s (median%s) | agnocast | "
      "iceoryx | agnocast / iceoryx |\n|---|---|---|---|\n",
      icount ? "10^9 instructions" : "second", icount ? "" : " and 95 % interval");
  for (const auto& [label, run] : throughput["agnocast"].items()) {
    const json& ratio = at_path(throughput, {"vs_iceoryx", label.c_str()});
    std::string ratio_text = ratio.is_object() ? number(ratio["value"], "%.2f") : "—";
    if (ratio.is_object() && ratio["interval"].is_array()) {
      ratio_text += " (" + number(ratio["interval"][0], "%.2f") + "–" +
                    number(ratio["interval"][1], "%.2f") + ")";
    }
    std::printf("| %s, %s sent | %s | %s | %s |\n", label.c_str(),
                number(run["published"], "%.0f").c_str(), rate(run).c_str(),
                rate(at_path(throughput, {"iceoryx", label.c_str()})).c_str(), ratio_text.c_str());
  }
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
  for (const char* size : {"64 B", "64 MiB"})
    check.latency("python_subscriber_constant_bytes", size);
  // The request → response round trip and its two references; a smoke run
  // measures the smallest size only.
  const bool smoke = report.value("smoke", false);
  check.latency("agnocast_service", "64 B");
  if (!smoke) check.latency("agnocast_service", "4 MiB");
  check.latency("agnocast_ping_pong", "64 B");
  // The scale series: a smoke run measures their smallest points, icount
  // the rest.
  if (smoke) {
    check.latency("agnocast_beside_idle_topics", "100");
    check.latency("agnocast_with_processes_attached", "4");
    for (const char* who :
         {"agnocast_depth", "agnocast_publish_taken", "agnocast_publish_into_full_queue"}) {
      check.latency(who, "10");
    }
    check.latency("agnocast_publish_into_full_queues", "2");
    check.latency("agnocast_beside_other_publishers", "3");
    check.latency("agnocast_longest_topic_name", "64 B");
  } else if (icount) {
    for (const char* name :
         {"idle_topics_flatness", "attached_processes_flatness", "depth_flatness",
          "full_queue_depth_flatness", "other_publishers_flatness", "longest_topic_name"}) {
      check.ratio(name, true);
    }
  }
  if (smoke || icount) {
    for (const char* kind : {"topic_with_publisher", "publisher", "polling_subscriber",
                             "callback_subscriber", "held_entry"}) {
      check.positive({"kernel_memory", "bytes_per_object", kind, "slab"});
    }
  }
  check.latency("unix_socket_request_response", "1 B");
  check.ratio("service_vs_one_way", icount);
  if (!smoke) check.ratio("service_size_flatness", icount);
  // The slope's difference of p50s may be negative in a tiny smoke run, so
  // fanout_slope is only required to be there.
  for (const char* name :
       {"size_flatness", "size_flatness_iceoryx", "python_size_flatness", "vs_iceoryx",
        "vs_iceoryx_64", "vs_mqueue_floor", "vs_epoll_floor", "fanout_64"}) {
    check.ratio(name, icount);
  }
  check.at({"ratios", "fanout_slope"});
  if (!icount) {
    check.ratio("topics_64", false);
    check.ratio("vs_iceoryx_constant_bytes", false);
    check.at({"ratio_ci", "fanout_slope"});
    check.positive({"background", "delivered_per_s"});
  }
  // The seed's protocol: the publisher enters the kernel once per message and
  // wakes each subscriber not woken already (one still busy with an earlier
  // wake-up is not sent another: a loaded machine sees fewer sends than
  // subscribers); the subscriber waits, then enters the kernel.
  for (const char* run : {"qos_10", "qos_1"}) {
    check.syscalls(run, "publisher", {"ioctl", "mq_timedsend"}, "ioctl", 1, 1);
    check.syscalls(run, "publisher", {}, "mq_timedsend", 0, 1);
    // A receive takes what is there; releases ride on it or on one more call.
    check.syscalls(run, "subscriber", {"ioctl"}, "ioctl", 0, 2);
  }
  check.syscalls("qos_10_4_subscribers", "publisher", {"ioctl", "mq_timedsend"}, "ioctl", 1, 1);
  check.syscalls("qos_10_4_subscribers", "publisher", {}, "mq_timedsend", 0, 4);
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
  for (const char* size : {"64 B", "4 MiB"}) {
    for (const char* who : {"agnocast", "iceoryx"}) {
      check.positive({"throughput", who, size, "value"});
      check.positive({"throughput", who, size, "received_fraction"});
    }
    check.positive({"throughput", "vs_iceoryx", size, "value"});
  }
  if (!icount) {
    // Recording: the recorder's CPU per message, every file complete.
    for (const char* run : {"pointcloud2_4mib_20hz", "small_64b_1khz"}) {
      check.positive({"recording", run, "cpu_us_per_message"});
      check.positive({"recording", run, "recorded"});
      const json* complete = check.at({"recording", run, "complete"});
      if (complete && *complete != true) {
        check.errors.push_back(std::string("recording/") + run + ": the file is not complete");
      }
    }
  }
  // The cost of one message: the seed's protocol's calls timed, the references too.
  check.positive({"cost_breakdown", "latency_ns"});
  for (const char* reference : {"null_ioctl_ns", "getppid_ns", "mq_send_ns", "mq_receive_ns",
                                "epoll_wait_ready_ns", "mqueue_hop_epoll_ns"}) {
    check.positive({"cost_breakdown", "reference", reference});
  }
  check.positive({"cost_breakdown_service", "round_trip_ns"});
  check.positive({"cost_breakdown_service", "client", "library_ns"});
  check.positive({"cost_breakdown_service", "server", "library_ns"});
  const std::pair<const char*, const char*> essential[] = {
      {"publisher", "ioctl PUBLISH"}, {"publisher", "mq_send"}, {"subscriber", "ioctl RECEIVE"}};
  for (const auto& [side, name] : essential) {
    const json* calls = check.at({"cost_breakdown", side, "calls"});
    if (!calls) continue;
    bool timed = false;
    for (const json& call : *calls) timed = timed || (call["name"] == name && call["ns"] > 0);
    if (!timed) check.errors.push_back(std::string("cost_breakdown: no timed ") + name);
  }
  return check.errors;
}

void print_markdown(const json& report, const PlotLinks& plots) {
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
  print_plot(plots, "sizes");
  // Reports from before the send calls were timed have none.
  if (!icount && report.contains("send_call")) {
    const json& calls = report["send_call"];
    std::printf(
        "\nThe sender's send call (`publish()`, or the two writes of the socket), p50 in µs, "
        "and in how many samples the receiver had the message before that call returned, 64 MiB "
        "written:\n\n| | agnocast | iceoryx | Unix socket (copy) |\n|---|---|---|---|\n");
    auto send_cell = [&](const char* who, const std::string& label) -> std::string {
      if (!calls.contains(who) || !calls[who].contains(label)) return "—";
      const json& call = calls[who][label];
      char text[64];
      std::snprintf(text, sizeof text, "%.0f; %zu of %zu", call["p50_us"].get<double>(),
                    call["delivered_before_it_returned"].get<std::size_t>(),
                    call["samples"].get<std::size_t>());
      return text;
    };
    if (latency.contains("agnocast_constant_bytes")) {
      for (const auto& [label, stats] : latency["agnocast_constant_bytes"].items()) {
        std::printf("| %s | %s | %s | %s |\n", label.c_str(),
                    send_cell("agnocast_constant_bytes", label).c_str(),
                    send_cell("iceoryx_constant_bytes", label).c_str(),
                    send_cell("unix_socket_constant_bytes", label).c_str());
      }
    }
  }

  if (latency.contains("python_subscriber_constant_bytes")) {
    std::printf(
        "\n| one-way latency, %s (p50 / p99), C++ publisher to a Python callback, 64 MiB "
        "written before each sample | 64 B | 64 MiB |\n|---|---|---|\n"
        "| `sensor_msgs/PointCloud2`, read in place through numpy | %s | %s |\n",
        unit, cell(latency, "python_subscriber_constant_bytes", "64 B").c_str(),
        cell(latency, "python_subscriber_constant_bytes", "64 MiB").c_str());
  }

  // Reports from before the fan-out's publish() was timed have no such column.
  const json& publish_calls = at_path(report, {"send_call", "agnocast_fanout"});
  std::printf(
      "\n| publish to last delivery, %s (p50 / p99) | agnocast, 4 KiB | mqueue wake-ups, "
      "receivers in `epoll_wait` | agnocast publisher's own time in `publish()` (p50) |\n"
      "|---|---|---|---|\n",
      unit);
  if (latency.contains("agnocast_fanout")) {
    for (const auto& [label, stats] : latency["agnocast_fanout"].items()) {
      const json& call = at_path(publish_calls, {label.c_str(), "cpu_p50_us"});
      std::printf(
          "| %s subscriber(s) | %s | %s | %s |\n", label.c_str(),
          cell(latency, "agnocast_fanout", label).c_str(),
          cell(latency, "mqueue_fanout", label).c_str(),
          call.is_number() ? number(json(call.get<double>() * unit_per_us), "%.0f").c_str() : "—");
    }
  }
  print_plot(plots, "fanout");
  if (report.contains("publish_call_us")) {
    const json& fit = report["publish_call_us"];
    std::printf(
        "\nThe publisher's own time in `publish()` (its thread's CPU time, which leaves out the "
        "subscribers that run inside the call on one CPU), fitted over those points: %s + %s per "
        "subscriber woken, %s.\n",
        number(json(fit["base"].get<double>() * unit_per_us), "%.0f").c_str(),
        number(json(fit["per_subscriber"].get<double>() * unit_per_us), "%.0f").c_str(),
        icount ? "ns (instructions)" : "µs");
  }
  print_plot(plots, "publish_call");

  // Scale: the one-way 64 B latency beside what a large system registers.
  // icount mode only; reports from before they were measured have none.
  const std::tuple<const char*, const char*, const char*> scales[] = {
      {"agnocast_beside_idle_topics", "other topics registered, idle", "idle_topics"},
      {"agnocast_with_processes_attached", "processes attached in all", "processes_attached"}};
  for (const auto& [who, what, plot] : scales) {
    if (!latency.contains(who) || !latency[who].is_object()) continue;
    std::printf("\n| one-way 64 B, %s (p50 / p99), by %s | |\n|---|---|\n", unit, what);
    for (const auto& [label, stats] : latency[who].items()) {
      std::printf("| %s | %s |\n", label.c_str(), cell(latency, who, label).c_str());
    }
    print_plot(plots, plot);
  }

  // QoS depth, and publish() into full queues; icount mode only.
  if (latency.contains("agnocast_depth")) {
    std::printf(
        "\n| QoS depth of both sides, %s (p50 / p99) | one-way 64 B | `publish()`, the subscriber "
        "taking each message | `publish()` into its full queue (the oldest dropped) |\n"
        "|---|---|---|---|\n",
        unit);
    for (const auto& [label, stats] : latency["agnocast_depth"].items()) {
      std::printf("| %s | %s | %s | %s |\n", label.c_str(),
                  cell(latency, "agnocast_depth", label).c_str(),
                  cell(latency, "agnocast_publish_taken", label).c_str(),
                  cell(latency, "agnocast_publish_into_full_queue", label).c_str());
    }
  }
  print_plot(plots, "depth");
  print_limits(report, unit);
  print_kernel_memory(report);

  // Reports from before services were measured have none.
  if (latency.contains("agnocast_service")) {
    std::printf(
        "\n| request → response round trip, %s (p50 / p99) | 64 B | 4 MiB |\n|---|---|---|\n"
        "| agnocast service: `async_send_request()` to the response callback | %s | %s |\n"
        "| two one-way publishes: a ping and its pong on two agnocast topics | %s | |\n"
        "| Unix socket (`SOCK_SEQPACKET`, 1 B each way, both sides in `epoll_wait`) | %s | |\n",
        unit, cell(latency, "agnocast_service", "64 B").c_str(),
        cell(latency, "agnocast_service", "4 MiB").c_str(),
        cell(latency, "agnocast_ping_pong", "64 B").c_str(),
        cell(latency, "unix_socket_request_response", "1 B").c_str());
  }
  print_plot(plots, "service_sizes");

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

  // A run of selected series (agnocast-bench --series) has nothing more.
  if (!report.contains("throughput")) return;

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
  if (report.contains("cost_breakdown")) print_breakdown(report["cost_breakdown"]);
  if (report.contains("cost_breakdown_service")) {
    print_service_breakdown(report["cost_breakdown_service"]);
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
  print_throughput(report);
  if (report.contains("recording") && report["recording"].is_object()) {
    const json& recording = report["recording"];
    std::printf(
        "\nRecording with `agnocast-cli bag record` (compression %s), the recorder's CPU time "
        "(user + system, from its subscription to its exit) per recorded message:\n\n",
        recording.value("compression", std::string("zstd")).c_str());
    std::printf(
        "| recorded topic | published | in the file | lost | drops the recorder counted | "
        "recorder CPU µs per message | file MiB |\n|---|---|---|---|---|---|---|\n");
    const std::pair<const char*, const char*> runs[] = {
        {"pointcloud2_4mib_20hz", "PointCloud2, 4 MiB at 20 Hz"},
        {"small_64b_1khz", "64 B at 1 kHz"}};
    for (const auto& [key, title] : runs) {
      if (!recording.contains(key)) continue;
      const json& run = recording[key];
      std::printf("| %s | %s | %s | %s | %s | %s | %s |\n", title,
                  number(run["published"], "%.0f").c_str(), number(run["recorded"], "%.0f").c_str(),
                  number(run["lost"], "%.0f").c_str(),
                  number(run["dropped_reported"], "%.0f").c_str(),
                  number(run["cpu_us_per_message"], "%.1f").c_str(),
                  run["file_bytes"].is_number()
                      ? number(json(run["file_bytes"].get<double>() / 1048576.0), "%.1f").c_str()
                      : "—");
    }
  }
}

namespace {

// "met (value)" / "not met (value)" / "not measured".
std::string standing(const json& value, double target, const char* format,
                     const json& interval = json()) {
  if (!value.is_number()) return "not measured";
  const double upper = interval.is_array() && interval[1].is_number() ? interval[1].get<double>()
                                                                      : value.get<double>();
  std::string text = upper <= target ? "**met**: " : "**not met**: ";
  text += number(value, format);
  if (interval.is_array()) {
    text += " (95 % interval " + number(interval[0]) + "–" + number(interval[1]) + ")";
  }
  return text;
}

double calls_per_message(const json& report, const char* run, const char* side) {
  const json& value = at_path(report, {"syscalls_per_message", run, side});
  return value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

// p50 of the breakdown's call `name` on `side`, NaN when it has none.
double call_ns(const json& breakdown, const char* side, const std::string& name) {
  const json& calls = at_path(breakdown, {side, "calls"});
  if (calls.is_array()) {
    for (const json& call : calls) {
      if (call.value("name", std::string()) == name && call["ns"].is_number()) {
        return call["ns"].get<double>();
      }
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double number_or_nan(const json& value) {
  return value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

// Why the one-way latency targets stand where they do, from the cost
// breakdown: what of the window is the kernel's, what is left to the library.
void print_why_latency_stands(const json& icount) {
  const json& breakdown = icount["cost_breakdown"];
  const double publish = call_ns(breakdown, "publisher", "ioctl PUBLISH");
  const double receive = call_ns(breakdown, "subscriber", "ioctl RECEIVE");
  const double hop = number_or_nan(at_path(breakdown, {"reference", "mqueue_hop_epoll_ns"}));
  const double mq_receive = number_or_nan(at_path(breakdown, {"reference", "mq_receive_ns"}));
  const double floor =
      number_or_nan(at_path(icount, {"latency", "mqueue_epoll_floor", "1 B", "p50_us"}));
  const double ours = number_or_nan(at_path(icount, {"latency", "agnocast", "64 B", "p50_us"}));
  const double iceoryx = number_or_nan(at_path(icount, {"latency", "iceoryx", "64 B", "p50_us"}));
  if (std::isnan(publish) || std::isnan(receive) || std::isnan(hop) || std::isnan(mq_receive) ||
      std::isnan(ours)) {
    return;
  }
  // The floor's hop less its mq_receive: agnocast takes its notification after the callback.
  const double kernel_path = hop - mq_receive + publish + receive;
  const double budget = std::min(
      {12000.0, floor * 1000 * 1.5, std::isnan(iceoryx) ? 12000.0 : iceoryx * 1000 * 0.85});
  const double rest = ours * 1000 - kernel_path;
  const bool fits = rest <= budget - kernel_path;
  std::printf(
      "\nWhere the one-way time goes: agnocast's window holds the mqueue hop it shares with "
      "the floor (`mq_send` to the return from `epoll_wait`, %.0f instructions: the floor's "
      "%.0f less its `mq_receive`, which agnocast's subscriber makes after the callback) and "
      "its own two ioctls (PUBLISH %.0f, RECEIVE %.0f): %.0f before any of the library's user "
      "space runs.  The 64 B p50 is %.0f; the rest of the window, %.0f, is mostly the "
      "library's own code (the publish call on one side; the executor's wake-up, the receive "
      "loop and the callback's dispatch on the other).  The strictest of the three targets "
      "(12,000; 1.5 × the floor; 0.85 × iceoryx) is %.0f, which leaves that rest %.0f: %s.  "
      "Each further fan-out subscriber is woken by an `mq_send` of its own, as in the mqueue "
      "series, and then also makes its RECEIVE, takes its notification and runs the "
      "library's wake-up, all on the one vCPU before the last subscriber's callback.\n",
      hop - mq_receive, hop, publish, receive, kernel_path, ours * 1000, rest, budget,
      budget - kernel_path, fits ? "it fits" : "less than it takes now");
}

// What going further would take: the design's floor (one mqueue hop and two
// null ioctls) against where the one-way path stands, part by part.
void print_what_would_change(const json& icount) {
  const json& breakdown = icount["cost_breakdown"];
  const double publish = call_ns(breakdown, "publisher", "ioctl PUBLISH");
  const double receive = call_ns(breakdown, "subscriber", "ioctl RECEIVE");
  const double hop = number_or_nan(at_path(breakdown, {"reference", "mqueue_hop_epoll_ns"}));
  const double blocking_hop = number_or_nan(at_path(breakdown, {"reference", "mqueue_hop_ns"}));
  const double null_ioctl = number_or_nan(at_path(breakdown, {"reference", "null_ioctl_ns"}));
  const double mq_receive = number_or_nan(at_path(breakdown, {"reference", "mq_receive_ns"}));
  const double ours = number_or_nan(at_path(icount, {"latency", "agnocast", "64 B", "p50_us"}));
  if (std::isnan(publish) || std::isnan(receive) || std::isnan(hop) || std::isnan(null_ioctl) ||
      std::isnan(mq_receive) || std::isnan(blocking_hop) || std::isnan(ours)) {
    return;
  }
  // agnocast's subscriber takes its notification after the callback, so the
  // window holds the hop less its mq_receive.
  const double window_hop = hop - mq_receive;
  const double floor = window_hop + 2 * null_ioctl;
  const double library = ours * 1000 - window_hop - publish - receive;
  std::printf(
      "\n## What would have to change to go further\n\n"
      "The floor of this design is one mqueue hop and two ioctls that do nothing: %.0f "
      "instructions (the hop from `mq_send` to the return from `epoll_wait`, less the "
      "receiver's `mq_receive`, which agnocast's subscriber makes after the callback: %.0f; "
      "and two null ioctls of %.0f each). The 64 B one way is %.0f, %.0f above it:\n\n"
      "- PUBLISH does %.0f beyond a null ioctl: the topic's lock, an entry from the module's "
      "slab cache, a reference for each subscriber, the list of those to wake copied out. "
      "RECEIVE does %.0f beyond one: the subscriber's queue, the entry's publisher and pool, "
      "the held list. That bookkeeping in the kernel is what lets it clean up after a process "
      "that dies at any point; keeping it in shared memory instead would have subscribers "
      "write where today they only read (a subscriber maps a publisher's pool read-only).\n"
      "- The library's own code inside the window is %.0f (the publish call around its "
      "ioctl and `mq_send` on one side; the executor's wake-up, its receive loop and the "
      "callback's dispatch on the other; the cost breakdown above has each side's share).\n"
      "- The hop itself: a receiver asleep in `mq_receive` is woken in %.0f, against %.0f "
      "through `epoll_wait`. An executor that sleeps in `mq_receive` when it has one "
      "subscription and nothing else would save the difference, but would not wait on timers, "
      "other subscriptions or cancel; every executor waits in `epoll_wait` today.\n"
      "- Merging the wake-up into PUBLISH (the module waking the subscriber itself, instead of "
      "the publisher's `mq_send`) would save a system call entry and the mqueue's own locking. "
      "The notification through a POSIX queue is the protocol's (its queue names and message "
      "are normative), so that is a new protocol, not an optimisation.\n",
      floor, window_hop, null_ioctl, ours * 1000, ours * 1000 - floor, publish - null_ioctl,
      receive - null_ioctl, library, blocking_hop, hop);
}

// The service's two targets, each with the references it is set beside.
void print_round_trip_standing(const json& report, const char* format, bool with_interval) {
  const json& latency = report["latency"];
  auto interval = [&](const char* name) {
    return with_interval ? at_path(report, {"ratio_ci", name}) : json();
  };
  const double scale = with_interval ? 1 : 1000;  // µs, or ns in icount
  const char* unit_name = with_interval ? "µs" : "ns";
  auto p50 = [&](const char* who, const char* label) {
    return number_or_nan(at_path(latency, {who, label, "p50_us"})) * scale;
  };
  const double round_trip = p50("agnocast_service", "64 B");
  std::printf(
      "- a service's request → response round trip ≤ 2.2 × the one-way 64 B latency "
      "(`service_vs_one_way`): %s",
      standing(at_path(report, {"ratios", "service_vs_one_way"}), 2.2, format,
               interval("service_vs_one_way"))
          .c_str());
  if (!std::isnan(round_trip)) {
    const double ping_pong = p50("agnocast_ping_pong", "64 B");
    const double socket = p50("unix_socket_request_response", "1 B");
    std::printf(
        " (%.0f %s against %.0f one way; two one-way publishes: %.0f, the round trip %.2f × "
        "that; the Unix socket floor: %.0f, the round trip %.2f × that)",
        round_trip, unit_name, p50("agnocast", "64 B"), ping_pong, round_trip / ping_pong, socket,
        round_trip / socket);
  }
  std::printf(
      "\n- the round trip as fast at 4 MiB as at 64 B (`service_size_flatness` ≤ 1.02): %s\n",
      standing(at_path(report, {"ratios", "service_size_flatness"}), 1.02, format,
               interval("service_size_flatness"))
          .c_str());
}

// Where a service's round trip goes, from its breakdown: each side's timed
// calls and user space, the wake-ups, and the server's tail after its
// callback, which icount's one vCPU runs before the woken client.
void print_why_round_trip_stands(const json& icount) {
  const json& breakdown = icount["cost_breakdown_service"];
  if (!breakdown.is_object()) return;
  auto calls_of = [&](const char* side) {
    double sum = 0;
    std::string names;
    for (const json& call : at_path(breakdown, {side, "calls"})) {
      sum += number_or_nan(call["per_message"]) * number_or_nan(call["ns"]);
      names += (names.empty() ? "" : ", ") + call.value("name", std::string());
    }
    return std::pair{sum, names};
  };
  const auto [client_calls, client_names] = calls_of("client");
  const auto [server_calls, server_names] = calls_of("server");
  double callback_end = std::numeric_limits<double>::quiet_NaN(), tail = callback_end;
  for (const json& span : breakdown["timeline"]) {
    const std::string what = span.value("what", std::string());
    if (what == "server's callback") callback_end = number_or_nan(span["end_ns"]);
    if (what == "epoll_wait" && span.value("side", std::string()) == "server" &&
        number_or_nan(span["start_ns"]) > callback_end && std::isnan(tail)) {
      tail = number_or_nan(span["start_ns"]) - callback_end;
    }
  }
  std::printf(
      "\nWhere the round trip goes (the breakdown's run, %s ns, each timed call with two clock "
      "reads more): the client's calls (%s) %.0f and its user space %s (`async_send_request()`, "
      "the executor's wake-up and the answer's way through the pending request's promise to the "
      "callback); the server's calls (%s) %.0f and its user space %s; the two wake-ups' context "
      "switches %s.  On icount's one vCPU the woken client runs only once the server sleeps "
      "again, so the server's tail after its callback (the request's notification taken, back "
      "into `epoll_wait`: %.0f) is inside the window; on two cores it would overlap the "
      "client's wake-up.\n",
      number(breakdown["round_trip_ns"], "%.0f").c_str(), client_names.c_str(), client_calls,
      number(at_path(breakdown, {"client", "library_ns"}), "%.0f").c_str(), server_names.c_str(),
      server_calls, number(at_path(breakdown, {"server", "library_ns"}), "%.0f").c_str(),
      number(breakdown["switches_ns"], "%.0f").c_str(), tail);
}

}  // namespace

void print_tracing_cost(const json& combined) {
  const json& runs = at_path(combined, {"tracing_cost"});
  if (!runs.is_object()) return;
  const char* variants[] = {"traced", "module_untraced", "untraced"};
  struct Row {
    std::string label;
    double values[3];
  };
  std::vector<Row> rows;
  auto add_call = [&](const char* label, const char* side, const char* call) {
    Row row{label, {}};
    for (int i = 0; i < 3; ++i)
      row.values[i] = call_ns(at_path(runs, {variants[i], "cost_breakdown"}), side, call);
    rows.push_back(row);
  };
  auto add_latency = [&](const char* label, const char* size) {
    Row row{label, {}};
    for (int i = 0; i < 3; ++i) {
      row.values[i] =
          number_or_nan(at_path(runs, {variants[i], "latency", "agnocast", size, "p50_us"})) * 1000;
    }
    rows.push_back(row);
  };
  add_call("`ioctl` PUBLISH", "publisher", "ioctl PUBLISH");
  add_call("`ioctl` RECEIVE", "subscriber", "ioctl RECEIVE");
  add_latency("agnocast one way, 64 B, p50", "64 B");
  add_latency("agnocast one way, 4 KiB, p50", "4 KiB");
  auto change = [](double with, double without) {
    if (std::isnan(with) || std::isnan(without) || without <= 0) return std::string("—");
    char text[32];
    std::snprintf(text, sizeof text, "%+.2f %%", (with / without - 1) * 100);
    return std::string(text);
  };
  std::printf(
      "\n## What tracing costs while nobody traces\n\n"
      "In the same icount boot, agnocast's 64 B and 4 KiB series and the cost breakdown ran "
      "three more times: as built (the module's trace events disabled, libagnocast's LTTng-UST "
      "call sites and no session), with an `agnocast.ko` built without its trace events, and "
      "with a libagnocast built without its provider (`AGNOCAST_TRACING=OFF`) as well.  The "
      "events' cost is the first against the second; the provider's the second against the "
      "third.\n\n"
      "| ns (instructions) | as built | module without its events | and libagnocast without "
      "its provider | the events' cost | the provider's cost |\n|---|---|---|---|---|---|\n");
  auto ns = [](double value) { return std::isnan(value) ? "—" : number(json(value), "%.0f"); };
  for (const Row& row : rows) {
    std::printf("| %s | %s | %s | %s | %s | %s |\n", row.label.c_str(), ns(row.values[0]).c_str(),
                ns(row.values[1]).c_str(), ns(row.values[2]).c_str(),
                change(row.values[0], row.values[1]).c_str(),
                change(row.values[1], row.values[2]).c_str());
  }
  // The same build, the same series, earlier in the same boot: how far the
  // state a boot is in moves a p50 with no change to the code.
  const double earlier =
      number_or_nan(at_path(combined, {"icount", "latency", "agnocast", "64 B", "p50_us"})) * 1000;
  if (!std::isnan(earlier) && !std::isnan(rows[2].values[0])) {
    std::printf(
        "\nThe same build's 64 B p50 earlier in this boot (the latency table above) was %.0f; "
        "the first column's is %s against it.  That much a p50 moves with no change to the "
        "code, as the pages a sample meets, and the kernel's work on them, change with what "
        "ran before: a cost within that, or a negative one, is one these runs cannot tell from "
        "none.\n",
        earlier, change(rows[2].values[0], earlier).c_str());
  }
  auto within = [&](std::initializer_list<std::pair<double, double>> pairs) {
    bool measured = true, met = true;
    for (const auto& [with, without] : pairs) {
      if (std::isnan(with) || std::isnan(without) || without <= 0)
        measured = false;
      else if (with / without > 1.01)
        met = false;
    }
    return !measured ? "not measured" : met ? "**met**" : "**not met**";
  };
  std::printf(
      "\n- disabled trace events cost PUBLISH, RECEIVE and the one way at most 1 %%: %s\n"
      "- libagnocast's call sites with no session cost the one way at most 1 %%: %s\n",
      within({{rows[0].values[0], rows[0].values[1]},
              {rows[1].values[0], rows[1].values[1]},
              {rows[2].values[0], rows[2].values[1]},
              {rows[3].values[0], rows[3].values[1]}}),
      within({{rows[2].values[1], rows[2].values[2]}, {rows[3].values[1], rows[3].values[2]}}));
}

void print_readme(const json& combined, const std::map<std::string, PlotLinks>& plots) {
  const json& icount = combined["icount"];
  const json& ordinary = combined["ordinary"];
  std::printf(
      "<!-- generated by scripts/bench --write-readme from benchmarks/report.json: do not edit "
      "-->\n"
      "# Benchmarks\n\n"
      "This file and its plots (`plots/`) are generated by scripts/bench (`scripts/bench "
      "--write-readme`) from one report, `benchmarks/report.json` (%s), which holds a run in each "
      "mode; nobody edits them by hand. `scripts/bench --write-readme --from "
      "benchmarks/report.json` writes them again.\n\n",
      combined.value("date", std::string("undated")).c_str());

  std::printf("## Where it ran\n\n| | icount mode | ordinary mode |\n|---|---|---|\n");
  auto both = [&](const char* title, std::initializer_list<const char*> path, const char* fmt) {
    auto text = [&](const json& report) {
      const json& value = at_path(report, path);
      if (value.is_string()) return value.get<std::string>();
      return number(value, fmt);
    };
    std::printf("| %s | %s | %s |\n", title, text(icount).c_str(), text(ordinary).c_str());
  };
  both("host CPU", {"host", "cpu"}, "%g");
  both("QEMU", {"host", "qemu"}, "%g");
  both("QEMU accelerator flags", {"host", "qemu_flags"}, "%g");
  both("guest kernel", {"machine", "kernel"}, "%g");
  both("guest CPU", {"machine", "cpu"}, "%g");
  both("vCPUs", {"machine", "cpus"}, "%.0f");
  both("guest memory, MiB", {"machine", "memory_mib"}, "%.0f");
  both("clock source", {"machine", "clocksource"}, "%g");
  both("rounds", {"rounds"}, "%.0f");
  // A mode measured again alone keeps the other's run: each mode's date.
  auto date_of = [&](const char* mode) {
    const json& date = at_path(combined, {"dates", mode});
    return date.is_string() ? date.get<std::string>()
                            : combined.value("date", std::string("undated"));
  };
  std::printf("| date of the run | %s | %s |\n", date_of("icount").c_str(),
              date_of("ordinary").c_str());
  auto randomized = [](const json& report) {
    const json& value = at_path(report, {"machine", "address_randomization"});
    return value.is_boolean() ? (value.get<bool>() ? "on" : "off") : "on (not recorded)";
  };
  std::printf("| address randomization (ASLR) | %s | %s |\n", randomized(icount),
              randomized(ordinary));
  std::printf("| wall time of the run (boot included), s | %s | %s |\n",
              number(at_path(combined, {"elapsed_s", "icount"}), "%.0f").c_str(),
              number(at_path(combined, {"elapsed_s", "ordinary"}), "%.0f").c_str());
  auto load = [&](const char* mode) {
    const json& before = at_path(combined, {"host_load", mode, "before"});
    const json& after = at_path(combined, {"host_load", mode, "after"});
    if (!before.is_string() || !after.is_string()) return std::string("not recorded");
    return before.get<std::string>() + " → " + after.get<std::string>();
  };
  std::printf("| host load average (1, 5, 15 min), before → after, on %s host CPUs | %s | %s |\n\n",
              number(at_path(combined, {"host_load", "cpus"}), "%.0f").c_str(),
              load("icount").c_str(), load("ordinary").c_str());

  std::printf("%s", R"(## How to read them

Both modes boot Debian's kernel under QEMU's TCG emulation (no KVM) with
`agnocast.ko`, without slab debugging, and run `agnocast-bench` there: every
series in the same boot, so ratios compare like with like.

- **icount mode** (`scripts/bench --icount`): QEMU counts instructions, and
  guest time is instructions executed (1 ns each; idle time is skipped). A
  p50 repeats to the nanosecond from run to run, whatever the host does, so a
  change of 1 % is visible. It weighs every instruction the same: cache
  misses, TLB refills and page faults cost what their instructions cost, so it
  measures how much *work* a message takes, not how long real hardware takes.
  One vCPU (two make no progress under icount): publisher and subscriber take
  turns, so a latency here is the work between the publish call and the
  callback, the context switch included. **The latency tables, the ratios and
  the cost breakdown come from this mode**; its ratios are single values.
  `agnocast-bench --icount` runs without address randomization (as
  `setarch -R`): where a buffer falls within its page changes the kernel's
  per-page work, and with a randomized layout agnocast's 64 B p50 moved by
  up to 4 % between boots (within a boot its rounds still agree).
- **ordinary mode** (`scripts/bench`): two vCPUs, each a host thread, on a
  shared host: absolute times are several times native and swing with the
  other work on the machine (p99s of 10 ms and more are the host preempting
  the emulator). Series that need parallel cores are measured here —
  `topics_64` (63 busy topics beside the measured one) and fan-out under
  parallel load — over many short rounds in shuffled order (the table above
  says how many), each ratio with a 95 % bootstrap interval of its median over
  rounds; a target counts as met only when the whole interval is under it.

Latency is one way: from the publish call, payload already written, to the
first line of the subscriber's callback, one message in flight, both sides
asleep before each sample. The floors are timed the same way, from `mq_send`
to the receiver's return from `mq_receive`, the receiver waiting in
`mq_receive` (`vs_mqueue_floor`) or in `epoll_wait` first, as agnocast's
executor does (`vs_epoll_floor`). The size series write 64 MiB before every
sample (payload + scratch), for every size and transport. The Python series
times a C++ publisher of `sensor_msgs/PointCloud2` to the first line of a
Python subscription's callback (`time.monotonic_ns()` against the publish time
the library stamps), which then checks the message through the numpy view of
the publisher's memory; `python_size_flatness` is its 64 MiB p50 over its 64 B
p50. The fan-out series also time the publisher's `publish()` call and its
thread's CPU time in it (a clock read and a CPU-time read inside the window,
about 800 instructions at one subscriber; the slope is unchanged). The scale
series (icount) measure the 64 B series beside 1 to 10,000 idle topics (one
publisher each, 1,000 a process, the module loaded with
`max_topics_per_namespace=16384`) and with 2 to 200 processes attached.

The depth series (icount) give both sides a QoS depth of 1, 10, 100 and
1,024 (`qos_depth_max`) and time the 64 B one-way latency, and the
publisher's `publish()` call (wall time, a clock read either side) into one
polling subscriber of its own process that takes each message before the next
or never does: then its queue stays full, and every publish drops the oldest
entry, which the publisher reclaims. After each run the kernel's counters
(what `agnocast-cli topic info` shows) must agree: the queue as full as its
depth and every message beyond it dropped, or nothing left and nothing
dropped. The limits table reaches each limit of `<agnocast/limits.hpp>` a
message's path could feel, beside the same measurement far from it: a full
queue at the deepest depth, 1,024 full depth-1 queues of polling subscribers
(in two processes), 1,023 other publishers of the measured topic, and a topic
name of 245 characters. The other limits (node and type names, a schema's
size and nesting, an access policy's rules and principals) are checked once,
when an endpoint is made or a policy loaded, and no message meets them: they
are not timed. **Kernel memory** is read, not estimated: a process in a
memory cgroup of its own makes 250 objects of each kind, and memory.stat's
`slab` (the slab objects allocated for them, in bytes) and `kernel` (every
kernel page charged, so it scatters around `slab` by up to a page over the
250) are read after each kind, once the kernel's periodic flush of its per-CPU
counters has run. The module allocates everything with `GFP_KERNEL_ACCOUNT`;
a callback subscriber's figure includes its notification queue. A held entry
is one a publisher's window of depth 1,024 keeps.

**Throughput** sends messages back to back from one publisher to one
subscriber, each payload written (zeros), and counts what the subscriber
received between the first one's publish and the last one's arrival:
agnocast's subscriber keeps 1,000 (what it has no room for is dropped, the
newest never), iceoryx's queue holds 256, its maximum (its publisher waits
for a chunk when every one is queued or held: it has 512 of 1 KiB and 16 of
4 MiB). In icount mode a second is 10^9 instructions, so the rate is messages
per 10^9 instructions; the ordinary mode repeats each pair 7 times, for the
median and its interval.

A service's round trip is timed from `async_send_request()`, the request
already written, to the first line of the client's response callback, one
request in flight, both sides asleep (the client paused, the server in
`epoll_wait`) before each sample. The request and the response each carry the
payload; the server answers from its callback with a response it wrote before
the first request came (the deferred form's `send_response()`, so that, as
the request's, the response's bytes are written outside the window), and the
client writes 4 MiB before each sample at every size (payload + scratch).
Beside it, timed the same way: two one-way publishes (a 64 B ping on one
agnocast topic whose callback publishes a pong written beforehand on another,
to the pong's callback) and a Unix `SOCK_SEQPACKET` socket pair carrying one
byte each way, each side asleep in `epoll_wait` before it reads, as
agnocast's executor is. System calls are
counted (perf counters on the syscall tracepoints) in a run of their own;
CPU time per message (user + system, 1 message a millisecond) is taken
without counters for agnocast, iceoryx and the floor alike. iceoryx is
Debian's 2.0 with RouDi and a WaitSet (the subscriber sleeps).

The **cost breakdown** runs `agnocast-bench-breakdown`, which replaces the C
library's `ioctl`, `mq_send`, `mq_receive` and `epoll_wait` that libagnocast
calls with the same raw system calls timed in place (two vDSO clock reads
each), over 50 messages sent one at a time: each call's count and p50 time
per side, the library's own user-space time (`borrow_loaned_message()` and
`publish()` on the publisher, wake-up to callback and callback to next wait on
the subscriber, less the calls in them), and the message of median latency on
one timeline. The references are timed the same way in loops in the same
boot; the mqueue hops are the floors' p50s of the same run. Its `--service`
run times a service's 64 B round trip the same way (50 one at a time, the
server answering with a response written beforehand): the calls each side
makes within the window, each side's own user-space time in it, and what is
left, the context switches of the two wake-ups.

**Recording** (ordinary mode only: it is CPU time at a real rate) runs
`agnocast-cli bag record` with its defaults (zstd, chunks of about 1 MiB) on
one topic while one publisher sends a 4 MiB `sensor_msgs/PointCloud2` (x, y,
z, intensity float32 points on a spiral) at 20 Hz for 2 s, then 64 B at
1 kHz for 5 s; the recorder is stopped with SIGINT half a second after the
last message. Its CPU time (user + system) from its subscription to its exit
(the last messages and the file's summary included, its start-up not) is
divided by the messages in the file; under emulation it is several times
what the same work costs natively. "lost" is what was
published and is not in the file, "drops the recorder counted" what the
kernel dropped for the recorder's subscription (it fell behind by more than
its depth of 10). The recorder copies each message out as CDR, compresses
1 MiB chunks with zstd and writes them from one thread: when the emulated
vCPU it runs on gives it less CPU time per message than the rate leaves
(50 ms at 20 Hz, 1 ms at 1 kHz, shared with the publisher and the other
vCPU's work, on a host loaded as the table above says), it falls behind and
the kernel drops its oldest messages for it alone, the publisher never
waiting. Its CPU time per message here is emulated time; natively the same
work is several times cheaper, so the losses say what this emulated machine
sustains, not what a robot's computer does.

The ordinary mode shares the host with whatever else runs there: the table
above gives the host's load average before and after each mode. A load above
the number of host CPUs means the emulator's vCPU threads waited for a CPU,
and every wall-time figure of that mode grew with it; icount figures do not
depend on it.

)");

  std::printf("## icount mode: latency, ratios, cost\n\n");
  auto plots_of = [&](const char* mode) {
    const auto found = plots.find(mode);
    return found == plots.end() ? PlotLinks{} : found->second;
  };
  print_markdown(icount, plots_of("icount"));
  std::printf("\n## Ordinary mode: parallel cores, with intervals\n\n");
  print_markdown(ordinary, plots_of("ordinary"));

  // Where each target stands.
  const json& latency = icount["latency"];
  std::printf("\n## Where the targets stand\n\n");
  std::printf("In icount mode:\n\n");
  std::printf(
      "- agnocast 64 B one way ≤ 12,000 instructions: %s ns\n",
      standing(json(at_path(latency, {"agnocast", "64 B", "p50_us"}).is_number()
                        ? at_path(latency, {"agnocast", "64 B", "p50_us"}).get<double>() * 1000
                        : std::numeric_limits<double>::quiet_NaN()),
               12000, "%.0f")
          .c_str());
  std::printf("- `vs_iceoryx` ≤ 0.85 at 64 B: %s; at 4 KiB: %s\n",
              standing(at_path(icount, {"ratios", "vs_iceoryx_64"}), 0.85, "%.3f").c_str(),
              standing(at_path(icount, {"ratios", "vs_iceoryx"}), 0.85, "%.3f").c_str());
  std::printf("- `vs_epoll_floor` ≤ 1.5: %s\n",
              standing(at_path(icount, {"ratios", "vs_epoll_floor"}), 1.5, "%.3f").c_str());
  std::printf("- `size_flatness` ≤ 1.01: %s (iceoryx: %s)\n",
              standing(at_path(icount, {"ratios", "size_flatness"}), 1.01, "%.3f").c_str(),
              number(at_path(icount, {"ratios", "size_flatness_iceoryx"}), "%.3f").c_str());
  std::printf(
      "- a 64 MiB message reaches a Python callback as fast as 64 B "
      "(`python_size_flatness` ≤ 1.01): %s\n",
      standing(at_path(icount, {"ratios", "python_size_flatness"}), 1.01, "%.3f").c_str());
  const json& cpu = icount["cpu_us_per_message"];
  for (const char* side : {"publisher", "subscriber"}) {
    const json& ours = at_path(cpu, {"agnocast", side});
    const json& theirs = at_path(cpu, {"iceoryx", side});
    std::printf("- CPU per message ≤ iceoryx's, %s: %s µs against %s µs: %s\n", side,
                number(ours, "%.1f").c_str(), number(theirs, "%.1f").c_str(),
                ours.is_number() && theirs.is_number()
                    ? (ours.get<double>() <= theirs.get<double>() ? "**met**" : "**not met**")
                    : "not measured");
  }
  std::printf(
      "- extra cost per fan-out subscriber ≤ 1.2 × the plain mqueue wake-up's (`fanout_slope`): "
      "%s (%s against %s µs per subscriber; each subscriber checks its 4 KiB payload once "
      "all have it, outside the window)\n",
      standing(at_path(icount, {"ratios", "fanout_slope"}), 1.2, "%.2f").c_str(),
      number(at_path(icount, {"fanout_slope_us_per_subscriber", "agnocast"}), "%.1f").c_str(),
      number(at_path(icount, {"fanout_slope_us_per_subscriber", "mqueue"}), "%.1f").c_str());
  if (icount.contains("publish_call_us")) {
    std::printf(
        "- the publisher's own time in `publish()` linear in the subscribers it wakes, its "
        "constant printed: %s + %s per subscriber, ns (instructions)\n",
        number(json(at_path(icount, {"publish_call_us", "base"}).get<double>() * 1000), "%.0f")
            .c_str(),
        number(json(at_path(icount, {"publish_call_us", "per_subscriber"}).get<double>() * 1000),
               "%.0f")
            .c_str());
  }
  const double sub_10 = calls_per_message(icount, "qos_10", "subscriber");
  const double sub_1 = calls_per_message(icount, "qos_1", "subscriber");
  const double pub_4 = calls_per_message(icount, "qos_10_4_subscribers", "publisher");
  std::printf(
      "- subscriber ≤ 3 system calls per message at QoS 10 and QoS 1: %.2f and %.2f: %s; "
      "publisher 1 + N (N = 4 subscribers): %.2f: %s\n",
      sub_10, sub_1, sub_10 <= 3 && sub_1 <= 3 ? "**met**" : "**not met**", pub_4,
      pub_4 <= 5 ? "**met**" : "**not met**");
  std::printf(
      "- the one-way latency flat within 2 %% from 1 to 10,000 other topics registered "
      "(`idle_topics_flatness`): %s; from 2 to 200 processes attached "
      "(`attached_processes_flatness`): %s\n",
      standing(at_path(icount, {"ratios", "idle_topics_flatness"}), 1.02, "%.3f").c_str(),
      standing(at_path(icount, {"ratios", "attached_processes_flatness"}), 1.02, "%.3f").c_str());
  std::printf(
      "- nothing on the message path grows with the QoS depth, 1 to 1,024: one way "
      "(`depth_flatness`): %s; `publish()` into a full queue (`full_queue_depth_flatness`): %s; "
      "nor with 1,023 other publishers of the topic (`other_publishers_flatness`): %s, nor with "
      "a topic name of 245 characters (`longest_topic_name`): %s\n",
      standing(at_path(icount, {"ratios", "depth_flatness"}), 1.02, "%.3f").c_str(),
      standing(at_path(icount, {"ratios", "full_queue_depth_flatness"}), 1.02, "%.3f").c_str(),
      standing(at_path(icount, {"ratios", "other_publishers_flatness"}), 1.02, "%.3f").c_str(),
      standing(at_path(icount, {"ratios", "longest_topic_name"}), 1.02, "%.3f").c_str());
  print_round_trip_standing(icount, "%.3f", false);
  print_why_latency_stands(icount);
  print_why_round_trip_stands(icount);
  std::printf("\nIn ordinary mode (whole 95 %% interval under the target):\n\n");
  std::printf("- `size_flatness` ≤ 1.05: %s\n",
              standing(at_path(ordinary, {"ratios", "size_flatness"}), 1.05, "%.2f",
                       at_path(ordinary, {"ratio_ci", "size_flatness"}))
                  .c_str());
  std::printf("- `python_size_flatness` ≤ 1.05: %s\n",
              standing(at_path(ordinary, {"ratios", "python_size_flatness"}), 1.05, "%.2f",
                       at_path(ordinary, {"ratio_ci", "python_size_flatness"}))
                  .c_str());
  std::printf("- `vs_iceoryx` ≤ 1.0 on the 64 MiB-written series (64 B): %s\n",
              standing(at_path(ordinary, {"ratios", "vs_iceoryx_constant_bytes"}), 1.0, "%.2f",
                       at_path(ordinary, {"ratio_ci", "vs_iceoryx_constant_bytes"}))
                  .c_str());
  std::printf("- `topics_64` ≤ 1.2: %s\n",
              standing(at_path(ordinary, {"ratios", "topics_64"}), 1.2, "%.2f",
                       at_path(ordinary, {"ratio_ci", "topics_64"}))
                  .c_str());
  print_round_trip_standing(ordinary, "%.2f", true);
  std::printf("%s", R"(
Where icount and the ordinary mode disagree (agnocast and iceoryx close in
one, several times apart in the other, above all after 64 MiB of writes), the
difference is time icount does not weigh. `agnocast-bench --window-check`
measures where it goes: the 64 B series of agnocast, iceoryx, both mqueue
floors and the Unix socket, with and without 64 MiB written first, each
sample with the sender's send call timed (`publish()`, `mq_send`, the
socket's writes) and, with `--window-counters`, the kernel's counters over
it. Its figures below are from three ordinary-mode runs of their own (8 to
12 rounds, 16 to 24 samples per series each; host load average 9 to 10 on 2
CPUs), not from the report above; ranges are the spread of the three p50s.

- The guest kernel does the same work with and without the writes. Counted
  on every CPU from before the send to the ack (a fourth run, 5 rounds: page
  faults, TLB flushes at a switch and shootdowns, call-function and
  reschedule IPIs, context switches, migrations, `mmap`/`munmap`/`madvise`
  calls), agnocast's median sample after 64 MiB written has 2 user page
  faults, 4.5 switch flushes, 0.5 shootdowns, no reschedule IPI and 10
  context switches; without the writes 1.5, 4.5, 0.5, 0 and 10.5. iceoryx's
  medians are of the same size (0 to 0.5 user page faults, 2.5 to 3 switch
  flushes, 2 shootdowns, 8.5 to 17.5 context switches), and no counter grows
  with the writes.
- What grows is the sender's send call, for every transport: after 64 MiB
  written its p50 is 3.8 to 5.1 ms for agnocast's `publish()`, 1.1 to 2.2 ms
  for iceoryx's and 1.4 to 5.2 ms for a bare `mq_send`, against 0.1 to
  0.25 ms without. The emulator's vCPUs are threads of the host, and the host
  was overcommitted: over two of the runs each vCPU thread spent as long
  runnable but waiting for a host CPU as running (61 s waiting for 65 s run,
  and 36 s for 40 s; the host's `/proc/<pid>/task/<tid>/schedstat`). A
  host profile of QEMU over a run (28,000 samples) has 57 % in translated
  guest code and 36 % in QEMU, its software-TLB refill about 1 % and the
  whole C library under 2 %.
- Whether the receiver waits for that call depends on how it sleeps. Asleep
  in `epoll_wait`, as agnocast's executor is, it had the message before the
  sender's call returned in 2 of 60 samples (agnocast) and 0 of 60 (the bare
  mqueue floor with `epoll_wait`), so its latency is the whole stalled call
  and more: p50 4.7 to 6.5 ms and 3.5 to 6.5 ms. Woken by a futex (iceoryx)
  or asleep in `mq_receive`, it had it first in 42 and 40 of 60: p50 0.75 to
  1.05 ms and 0.58 to 0.75 ms. Linux's `mq_send` wakes a receiver blocked in
  `mq_receive` after it has released the queue's lock, but wakes an epoll
  waiter while holding it (`ipc/mqueue.c`); what the woken epoll waiter then
  waits for was not measured.

So the gap is not work agnocast does: the mqueue floor with `epoll_wait`,
with no agnocast code at all, loses the same milliseconds (p50 4.8 ms after
64 MiB written against 4.7 ms for agnocast in the same run). It is time the
emulator's vCPUs wait for the host's CPUs, which a wake-up through epoll
cannot overlap. Removing it from agnocast would take a subscriber that sleeps
in `mq_receive` itself instead of `epoll_wait`, which the executor (any
number of subscriptions, timers, cancel) does not do. Until then the ordinary
mode's 64 MiB-written ratios (`size_flatness`, `vs_iceoryx_constant_bytes`)
measure the host's scheduling of the emulator, not agnocast or real hardware.
The table of send calls under the 64 MiB-written latencies (in reports that
have it) gives the same two figures for every size, from the report's own
run.

In the ordinary mode a QoS 1 subscriber on a loaded host loses messages (a
newer one replaces the one it had not taken yet); each notification still
wakes it once, so its calls per *delivered* message can exceed three, while
icount, where nothing is lost, shows the calls per wake-up.

A subscriber's system calls per message in steady state are the executor's
`epoll_wait`, the notification taken (`mq_timedreceive`) and one RECEIVE
ioctl that also carries the release of the message before: the deferred
release's deadline (at most 4 ms after the wake-up that left it) is the
timeout of the executor's wait, so no timer is set, read or woken for while
messages keep coming.
)");
  print_tracing_cost(combined);
  print_what_would_change(icount);
}

}  // namespace agnocast::bench
