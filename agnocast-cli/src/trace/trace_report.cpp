#include "trace/trace_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "cli.hpp"
#include "trace/chrome_trace.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

// Microseconds, as the trace has them.
json percentiles(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const auto at = [&](double fraction) {
    const auto rank =
        static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(values.size())));
    return std::round(values[std::max<std::size_t>(rank, 1) - 1] * 1e3) / 1e3;
  };
  if (values.empty()) {
    return {{"min_us", nullptr},
            {"p50_us", nullptr},
            {"p99_us", nullptr},
            {"max_us", nullptr},
            {"count", 0}};
  }
  return {{"min_us", at(0)},
          {"p50_us", at(0.5)},
          {"p99_us", at(0.99)},
          {"max_us", at(1)},
          {"count", values.size()}};
}

struct Slice {
  int pid = 0;
  int tid = 0;
  double start = 0;
  double end = 0;
  std::string topic;  // empty for a timer
};

struct Flow {
  std::string topic;
  std::string node;  // the subscriber's
  int from_pid = 0, from_tid = 0, to_pid = 0, to_tid = 0;
  double published = 0, started = 0;
};

std::string format_us(const json& value) {
  if (value.is_null()) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", value.get<double>());
  return text;
}

}  // namespace

json trace_report_json(const json& trace, const std::vector<std::string>& path) {
  const auto marked = [&] {
    if (!trace.is_object() || !trace.contains("traceEvents") || !trace.contains("otherData")) {
      return false;
    }
    const json& other = trace["otherData"];
    return trace["traceEvents"].is_array() && other.is_object() &&
           other.contains("agnocast_trace") && other["agnocast_trace"].is_number_integer() &&
           other["agnocast_trace"] == chrome_trace_format;
  };
  if (!marked()) {
    throw InputError(
        "not a trace agnocast-cli trace record wrote (no traceEvents with otherData.agnocast_trace "
        "= 1): record one with agnocast-cli trace record -o FILE");
  }
  if (path.size() == 1) throw InputError("--path needs two topics at least, e.g. --path /a,/b");
  std::map<std::uint64_t, json> starts;
  std::vector<Flow> flows;
  std::vector<Slice> slices;
  std::map<std::pair<std::string, std::string>, std::vector<double>> durations;
  try {
    for (const json& event : trace["traceEvents"]) {
      const std::string phase = event.value("ph", "");
      if (phase == "s" && event.value("cat", "") == "flow") {
        starts[event.at("id").get<std::uint64_t>()] = event;
      } else if (phase == "f" && event.value("cat", "") == "flow") {
        const auto start = starts.find(event.at("id").get<std::uint64_t>());
        if (start == starts.end()) continue;
        const json& from = start->second;
        flows.push_back({event.at("name"), event.at("args").value("node", ""), from.at("pid"),
                         from.at("tid"), event.at("pid"), event.at("tid"), from.at("ts"),
                         event.at("ts")});
      } else if (phase == "X" && event.value("cat", "") == "callback") {
        const json& args = event.at("args");
        const double start = event.at("ts");
        const double duration = event.at("dur");
        slices.push_back(
            {event.at("pid"), event.at("tid"), start, start + duration, args.value("topic", "")});
        durations[{event.at("name"), args.value("node", "")}].push_back(duration);
      }
    }
  } catch (const json::exception& error) {
    throw InputError(
        std::string("the trace has an event without the fields trace record writes: ") +
        error.what());
  }

  json report = {{"topics", json::array()}, {"callbacks", json::array()}};
  std::map<std::pair<std::string, std::string>, std::vector<double>> delays;
  for (const Flow& flow : flows)
    delays[{flow.topic, flow.node}].push_back(flow.started - flow.published);
  for (const auto& [key, values] : delays) {
    json row = percentiles(values);
    row["topic"] = key.first;
    row["node"] = key.second;
    report["topics"].push_back(row);
  }
  for (const auto& [key, values] : durations) {
    json row = percentiles(values);
    row["callback"] = key.first;
    row["node"] = key.second;
    report["callbacks"].push_back(row);
  }
  if (path.empty()) return report;

  // A chain: a flow on path[i] ends in a callback slice; the publishes on
  // path[i + 1] made inside that slice start the next stage's flows.
  std::map<std::tuple<int, int, double>, const Slice*> slice_at;  // by pid, tid, start
  for (const Slice& slice : slices) slice_at[{slice.pid, slice.tid, slice.start}] = &slice;
  // Flows by topic and publishing thread, in publish order.
  std::map<std::tuple<std::string, int, int>, std::vector<const Flow*>> published_by;
  for (const Flow& flow : flows)
    published_by[{flow.topic, flow.from_pid, flow.from_tid}].push_back(&flow);
  for (auto& [key, list] : published_by) {
    std::stable_sort(list.begin(), list.end(),
                     [](const Flow* a, const Flow* b) { return a->published < b->published; });
  }
  std::vector<double> chains;
  std::uint64_t begun = 0, broken = 0;
  // Each publish on the first topic, with the flows it started.
  std::map<std::tuple<int, int, double>, std::vector<const Flow*>> firsts;
  for (const Flow& flow : flows) {
    if (flow.topic == path.front())
      firsts[{flow.from_pid, flow.from_tid, flow.published}].push_back(&flow);
  }
  for (const auto& [publish, first_stage] : firsts) {
    ++begun;
    std::vector<const Flow*> stage = first_stage;
    for (std::size_t next = 1; next < path.size() && !stage.empty(); ++next) {
      std::vector<const Flow*> following;
      for (const Flow* flow : stage) {
        const auto inside = slice_at.find({flow->to_pid, flow->to_tid, flow->started});
        if (inside == slice_at.end() || inside->second->topic != flow->topic) continue;
        const Slice& slice = *inside->second;
        const auto candidates = published_by.find({path[next], slice.pid, slice.tid});
        if (candidates == published_by.end()) continue;
        const auto& list = candidates->second;
        auto from = std::lower_bound(list.begin(), list.end(), slice.start,
                                     [](const Flow* f, double t) { return f->published < t; });
        for (; from != list.end() && (*from)->published <= slice.end; ++from) {
          following.push_back(*from);
        }
      }
      stage = std::move(following);
    }
    if (stage.empty()) ++broken;
    for (const Flow* last : stage) chains.push_back(last->started - std::get<2>(publish));
  }
  json chain = percentiles(chains);
  chain["topics"] = path;
  chain["published"] = begun;
  chain["incomplete"] = broken;
  report["path"] = chain;
  return report;
}

json trace_report_file(const std::string& file, const std::vector<std::string>& path) {
  std::ifstream in(file);
  if (!in) throw InputError("cannot read " + file);
  json trace;
  try {
    in >> trace;
  } catch (const json::exception&) {
    throw InputError(file + " is not JSON: not a trace agnocast-cli trace record wrote");
  }
  return trace_report_json(trace, path);
}

std::string trace_report_table(const json& report) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof line, "%-32s %-20s %10s %10s %10s %10s %9s\n", "TOPIC", "NODE",
                "MIN_US", "P50_US", "P99_US", "MAX_US", "MESSAGES");
  out << "publish -> callback start\n" << line;
  for (const json& row : report["topics"]) {
    std::snprintf(line, sizeof line, "%-32s %-20s %10s %10s %10s %10s %9zu\n",
                  row["topic"].get<std::string>().c_str(), row["node"].get<std::string>().c_str(),
                  format_us(row["min_us"]).c_str(), format_us(row["p50_us"]).c_str(),
                  format_us(row["p99_us"]).c_str(), format_us(row["max_us"]).c_str(),
                  row["count"].get<std::size_t>());
    out << line;
  }
  std::snprintf(line, sizeof line, "%-32s %-20s %10s %10s %10s %10s %9s\n", "CALLBACK", "NODE",
                "MIN_US", "P50_US", "P99_US", "MAX_US", "CALLS");
  out << "\ncallback duration\n" << line;
  for (const json& row : report["callbacks"]) {
    std::snprintf(line, sizeof line, "%-32s %-20s %10s %10s %10s %10s %9zu\n",
                  row["callback"].get<std::string>().c_str(),
                  row["node"].get<std::string>().c_str(), format_us(row["min_us"]).c_str(),
                  format_us(row["p50_us"]).c_str(), format_us(row["p99_us"]).c_str(),
                  format_us(row["max_us"]).c_str(), row["count"].get<std::size_t>());
    out << line;
  }
  if (report.contains("path")) {
    const json& path = report["path"];
    std::string topics;
    for (const json& topic : path["topics"])
      topics += (topics.empty() ? "" : " -> ") + topic.get<std::string>();
    out << "\npath " << topics << " (first publish -> last callback start)\n";
    std::snprintf(line, sizeof line, "%10s %10s %10s %10s %9s %9s %10s\n", "MIN_US", "P50_US",
                  "P99_US", "MAX_US", "CHAINS", "PUBLISHED", "INCOMPLETE");
    out << line;
    std::snprintf(line, sizeof line, "%10s %10s %10s %10s %9zu %9zu %10zu\n",
                  format_us(path["min_us"]).c_str(), format_us(path["p50_us"]).c_str(),
                  format_us(path["p99_us"]).c_str(), format_us(path["max_us"]).c_str(),
                  path["count"].get<std::size_t>(), path["published"].get<std::size_t>(),
                  path["incomplete"].get<std::size_t>());
    out << line;
  }
  return out.str();
}

}  // namespace agnocast::cli
