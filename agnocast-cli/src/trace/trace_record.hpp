// agnocast-cli trace record: libagnocast's LTTng-UST events of every agnocast
// process (through an LTTng session), the module's tracepoints (through a
// tracefs instance of its own) and each topic's entry counts (sampled ten
// times a second), written as one Chrome trace-event JSON file.
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "inspection_source.hpp"

namespace agnocast::cli {

struct TraceRecordOptions {
  std::optional<double> duration_s;   // until SIGINT/SIGTERM when empty
  std::string output;                 // ./agnocast-trace-<time>.json when empty
  std::optional<std::string> topics;  // ECMAScript regex over topic names
  bool json = false;                  // the summary as one JSON object
};

// Throws InputError for a bad --topics, CliError when tracing cannot start
// (what is missing: a tool, root or the tracing group).
int trace_record(InspectionSource& source, const TraceRecordOptions& options, std::ostream& out);

}  // namespace agnocast::cli
