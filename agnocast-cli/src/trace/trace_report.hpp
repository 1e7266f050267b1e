// agnocast-cli trace report FILE [--path /a,/b,...]: from a trace that
// `trace record` wrote, the latency from publish to callback start per topic
// and subscribing node, each callback's duration, and with --path the latency
// along a chain of topics: from a publish on the first to the start of the
// callback on the last, through callbacks that publish on the next topic.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace agnocast::cli {

// Throws InputError when `trace` is not a trace `trace record` wrote, or the
// path names fewer than two topics.
nlohmann::json trace_report_json(const nlohmann::json& trace, const std::vector<std::string>& path);
// Reads and parses FILE first; InputError when it cannot be read or parsed.
nlohmann::json trace_report_file(const std::string& file, const std::vector<std::string>& path);
std::string trace_report_table(const nlohmann::json& report);

}  // namespace agnocast::cli
