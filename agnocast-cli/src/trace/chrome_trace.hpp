// A recorded trace as Chrome trace-event JSON, which ui.perfetto.dev and
// chrome://tracing open: a track per process and thread, an `X` slice per
// callback (and per executor wait), a flow (`s` → `f`) from each publish to
// each callback it caused, the module's events as instants, and counters of
// each topic's held and unreceived entries. `trace report` reads it back.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "trace/trace_event.hpp"

namespace agnocast::cli {

// A topic's entries at one moment, summed over its subscribers.
struct EntryCounts {
  std::int64_t time_ns = 0;
  std::string topic;
  std::uint64_t held = 0;        // received and not yet released
  std::uint64_t unreceived = 0;  // queued and not yet received
};

struct RecordedTrace {
  std::vector<TraceEvent> library;  // parse_lttng_text()
  std::vector<TraceEvent> kernel;   // parse_tracefs_text()
  std::vector<EntryCounts> counts;
  // Node names by topic and endpoint id, from the kernel: they name what a
  // process made before the recording began (its init events are not in it).
  std::map<std::pair<std::string, std::uint32_t>, std::string> publisher_nodes, subscriber_nodes;
  std::optional<std::regex> topics;  // only the topics this matches, when set
};

// The marker trace report looks for: {"otherData": {"agnocast_trace": 1}}.
inline constexpr int chrome_trace_format = 1;

nlohmann::json chrome_trace(const RecordedTrace& trace);

}  // namespace agnocast::cli
