#include "trace/chrome_trace.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace agnocast::cli {
namespace {

using nlohmann::json;

// The counters' track: no process of the machine has pid 0.
constexpr int counters_pid = 0;

double micros(std::int64_t ns) { return static_cast<double>(ns) / 1e3; }

// An object of the library, by process and address.
using Handle = std::pair<int, std::int64_t>;

// What a publisher, subscription or timer is (for a timer, `topic` holds its name).
struct Endpoint {
  std::string topic;
  std::string node;
};

// A subscription's take, which its callable_start follows on the thread.
struct Take {
  std::int64_t subscription = 0;
  std::int64_t entry = 0;
  std::string topic;
  std::uint32_t subscriber_id = 0;
};

struct Open {
  std::int64_t callable = 0;
  std::int64_t start_ns = 0;
  std::optional<Take> take;
};

struct Publish {
  int pid = 0;
  int tid = 0;
  std::int64_t time_ns = 0;
};

std::string node_of(const std::map<std::pair<std::string, std::uint32_t>, std::string>& nodes,
                    const std::string& topic, std::optional<std::int64_t> id) {
  if (!id) return {};
  const auto found = nodes.find({topic, static_cast<std::uint32_t>(*id)});
  return found == nodes.end() ? std::string() : found->second;
}

class Converter {
 public:
  explicit Converter(const RecordedTrace& trace) : trace_(trace) {}

  json convert() {
    std::vector<const TraceEvent*> library;
    for (const TraceEvent& event : trace_.library) library.push_back(&event);
    std::stable_sort(library.begin(), library.end(),
                     [](const auto* a, const auto* b) { return a->time_ns < b->time_ns; });
    for (const TraceEvent* event : library) learn(*event);
    for (const TraceEvent* event : library) follow(*event);
    for (const TraceEvent& event : trace_.kernel) kernel_instant(event);
    for (const EntryCounts& counts : trace_.counts) counter(counts);
    name_tracks();
    return json{{"traceEvents", std::move(events_)},
                {"displayTimeUnit", "ns"},
                {"otherData",
                 {{"agnocast_trace", chrome_trace_format},
                  {"flows", flows_},
                  {"callbacks", callbacks_},
                  {"library_events", trace_.library.size()},
                  {"kernel_events", trace_.kernel.size()}}}};
  }

 private:
  bool wanted(const std::string& topic) const {
    return !trace_.topics || std::regex_search(topic, *trace_.topics);
  }

  void see(const TraceEvent& event) {
    if (!event.process.empty()) {
      if (event.pid == event.tid || !process_names_.contains(event.pid)) {
        process_names_[event.pid] = event.process;
      }
      thread_names_[{event.pid, event.tid}] = event.process;
    } else {
      process_names_.try_emplace(event.pid);
      thread_names_.try_emplace({event.pid, event.tid});
    }
  }

  // The init events: what each handle is.
  void learn(const TraceEvent& event) {
    const auto handle = [&](const char* key) {
      return Handle{event.pid, event.number(key).value_or(0)};
    };
    if (event.name == "agnocast_node_init") {
      nodes_[handle("node_handle")] = event.text("node_name");
    } else if (event.name == "agnocast_publisher_init") {
      publishers_[handle("publisher_handle")] = {event.text("topic_name"),
                                                 nodes_[handle("node_handle")]};
    } else if (event.name == "agnocast_subscription_init") {
      subscriptions_[handle("subscription_handle")] = {event.text("topic_name"),
                                                       nodes_[handle("node_handle")]};
    } else if (event.name == "agnocast_timer_init") {
      const double period_ms = static_cast<double>(event.number("period").value_or(0)) / 1e6;
      char name[64];
      std::snprintf(name, sizeof name, "timer %g ms", period_ms);
      timers_[handle("timer_handle")] = {name, nodes_[handle("node_handle")]};
    }
  }

  void follow(const TraceEvent& event) {
    see(event);
    const std::pair<int, int> thread{event.pid, event.tid};
    if (event.name == "agnocast_publish") {
      const auto known = publishers_.find({event.pid, event.number("publisher_handle").value_or(0)});
      std::string topic = event.text("topic_name");
      if (topic.empty() && known != publishers_.end()) topic = known->second.topic;
      if (topic.empty() || !wanted(topic)) return;
      const std::string node =
          known != publishers_.end()
              ? known->second.node
              : node_of(trace_.publisher_nodes, topic, event.number("publisher_id"));
      const std::int64_t entry = event.number("entry_id").value_or(0);
      publishes_[{topic, entry}] = {event.pid, event.tid, event.time_ns};
      events_.push_back({{"ph", "X"},
                         {"cat", "publish"},
                         {"name", "publish " + topic},
                         {"pid", event.pid},
                         {"tid", event.tid},
                         {"ts", micros(event.time_ns)},
                         {"dur", 0},
                         {"args", {{"topic", topic}, {"node", node}, {"entry_id", entry}}}});
    } else if (event.name == "agnocast_take") {
      Take take{event.number("subscription_handle").value_or(0),
                event.number("entry_id").value_or(0), event.text("topic_name"),
                static_cast<std::uint32_t>(event.number("subscriber_id").value_or(0))};
      if (take.topic.empty()) {
        const auto known = subscriptions_.find({event.pid, take.subscription});
        if (known != subscriptions_.end()) take.topic = known->second.topic;
      }
      last_take_[thread] = std::move(take);
    } else if (event.name == "agnocast_callable_start") {
      Open open{event.number("callable").value_or(0), event.time_ns, std::nullopt};
      const auto take = last_take_.find(thread);
      if (take != last_take_.end() && take->second.subscription == open.callable) {
        open.take = std::move(take->second);
        last_take_.erase(take);
      }
      open_[thread].push_back(open);
    } else if (event.name == "agnocast_callable_end") {
      auto& stack = open_[thread];
      const std::int64_t callable = event.number("callable").value_or(0);
      // A start before the recording began has no slice.
      while (!stack.empty() && stack.back().callable != callable) stack.pop_back();
      if (stack.empty()) return;
      const Open open = stack.back();
      stack.pop_back();
      slice(event, open);
    } else if (event.name == "agnocast_executor_wait") {
      waits_[thread] = event.time_ns;
    } else if (event.name == "agnocast_executor_wake") {
      const auto wait = waits_.find(thread);
      if (wait == waits_.end()) return;
      events_.push_back({{"ph", "X"},
                         {"cat", "executor"},
                         {"name", "executor wait"},
                         {"pid", event.pid},
                         {"tid", event.tid},
                         {"ts", micros(wait->second)},
                         {"dur", micros(event.time_ns - wait->second)},
                         {"args", {{"ready", event.number("ready").value_or(0)}}}});
      waits_.erase(wait);
    }
  }

  // A callback's slice, and the flow from the publish of its entry.
  void slice(const TraceEvent& end, const Open& open) {
    const Handle handle{end.pid, open.callable};
    json args;
    std::string name;
    const auto sub = subscriptions_.find(handle);
    if (open.take && !open.take->topic.empty()) {
      const Take& take = *open.take;
      if (!wanted(take.topic)) return;
      name = "callback " + take.topic;
      args = {{"topic", take.topic},
              {"node", sub != subscriptions_.end()
                           ? sub->second.node
                           : node_of(trace_.subscriber_nodes, take.topic, take.subscriber_id)},
              {"entry_id", take.entry}};
    } else if (sub != subscriptions_.end()) {
      if (!wanted(sub->second.topic)) return;
      name = "callback " + sub->second.topic;
      args = {{"topic", sub->second.topic}, {"node", sub->second.node}};
    } else if (const auto timer = timers_.find(handle); timer != timers_.end()) {
      name = timer->second.topic;
      args = {{"node", timer->second.node}};
    } else {
      // A timer made before the recording began: nothing names it.
      char text[32];
      std::snprintf(text, sizeof text, "0x%llx", static_cast<unsigned long long>(open.callable));
      name = "callback";
      args = {{"callable", text}};
    }
    ++callbacks_;
    events_.push_back({{"ph", "X"},
                       {"cat", "callback"},
                       {"name", name},
                       {"pid", end.pid},
                       {"tid", end.tid},
                       {"ts", micros(open.start_ns)},
                       {"dur", micros(end.time_ns - open.start_ns)},
                       {"args", args}});
    if (!open.take || open.take->topic.empty()) return;
    const std::string& topic = open.take->topic;
    const std::int64_t entry = open.take->entry;
    const auto publish = publishes_.find({topic, entry});
    if (publish == publishes_.end()) return;
    const std::uint64_t id = ++flows_;
    const Publish& from = publish->second;
    events_.push_back({{"ph", "s"}, {"cat", "flow"}, {"name", topic}, {"id", id},
                       {"pid", from.pid}, {"tid", from.tid}, {"ts", micros(from.time_ns)},
                       {"args", {{"entry_id", entry}}}});
    events_.push_back({{"ph", "f"}, {"bp", "e"}, {"cat", "flow"}, {"name", topic}, {"id", id},
                       {"pid", end.pid}, {"tid", end.tid}, {"ts", micros(open.start_ns)},
                       {"args", {{"entry_id", entry}, {"node", args["node"]}}}});
  }

  void kernel_instant(const TraceEvent& event) {
    const std::string topic = event.text("topic");
    if (!topic.empty() && !wanted(topic)) return;
    see(event);
    json args = json::object();
    for (const auto& [key, value] : event.fields) args[key] = value;
    events_.push_back(
        {{"ph", "i"},
         {"s", "t"},
         {"cat", "kernel"},
         {"name", topic.empty() ? "kernel " + event.name : "kernel " + event.name + " " + topic},
         {"pid", event.pid},
         {"tid", event.tid},
         {"ts", micros(event.time_ns)},
         {"args", args}});
  }

  void counter(const EntryCounts& counts) {
    if (!wanted(counts.topic)) return;
    has_counters_ = true;
    events_.push_back({{"ph", "C"},
                       {"name", "entries " + counts.topic},
                       {"pid", counters_pid},
                       {"ts", micros(counts.time_ns)},
                       {"args", {{"held", counts.held}, {"unreceived", counts.unreceived}}}});
  }

  void name_tracks() {
    for (const auto& [pid, name] : process_names_) {
      events_.push_back({{"ph", "M"},
                         {"name", "process_name"},
                         {"pid", pid},
                         {"tid", pid},
                         {"args", {{"name", name.empty() ? "pid " + std::to_string(pid) : name}}}});
    }
    for (const auto& [thread, name] : thread_names_) {
      events_.push_back(
          {{"ph", "M"},
           {"name", "thread_name"},
           {"pid", thread.first},
           {"tid", thread.second},
           {"args",
            {{"name", (name.empty() ? "thread" : name) + " " + std::to_string(thread.second)}}}});
    }
    if (has_counters_) {
      events_.push_back({{"ph", "M"},
                         {"name", "process_name"},
                         {"pid", counters_pid},
                         {"tid", counters_pid},
                         {"args", {{"name", "agnocast entries"}}}});
    }
  }

  const RecordedTrace& trace_;
  json events_ = json::array();
  std::map<Handle, std::string> nodes_;
  std::map<Handle, Endpoint> publishers_, subscriptions_, timers_;
  std::map<std::pair<std::string, std::int64_t>, Publish> publishes_;  // by topic and entry
  std::map<std::pair<int, int>, Take> last_take_;
  std::map<std::pair<int, int>, std::vector<Open>> open_;
  std::map<std::pair<int, int>, std::int64_t> waits_;
  std::map<int, std::string> process_names_;
  std::map<std::pair<int, int>, std::string> thread_names_;
  std::uint64_t flows_ = 0;
  std::uint64_t callbacks_ = 0;
  bool has_counters_ = false;
};

}  // namespace

json chrome_trace(const RecordedTrace& trace) { return Converter(trace).convert(); }

}  // namespace agnocast::cli
