// One event of a recorded trace, whichever side it came from: libagnocast's
// LTTng-UST events as babeltrace2 prints them, or the module's tracepoints
// as tracefs prints them. Times are CLOCK_MONOTONIC nanoseconds on both.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace agnocast::cli {

struct TraceEvent {
  std::int64_t time_ns = 0;
  int pid = 0;
  int tid = 0;
  std::string process;  // the command name, when the source gives it
  std::string name;     // "agnocast_publish" (library) or "publish" (kernel)
  std::map<std::string, std::string, std::less<>> fields;  // as printed, strings unquoted

  // A field read as an integer (decimal or 0x hex); nullopt when absent or not a number.
  std::optional<std::int64_t> number(std::string_view key) const;
  std::string text(std::string_view key) const;  // empty when absent
};

// babeltrace2's text output (`--clock-cycles --no-delta`) of a trace holding
// the agnocast provider's events with the vpid, vtid and procname contexts;
// other lines are skipped.
std::vector<TraceEvent> parse_lttng_text(std::string_view text);

// A tracefs instance's `trace` file (trace_clock mono); lines of events other
// than the module's are skipped. `pid` is the field the event carries, `tid`
// the task that fired it.
std::vector<TraceEvent> parse_tracefs_text(std::string_view text);

}  // namespace agnocast::cli
