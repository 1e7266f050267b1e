// What a report must hold whatever the machine's speed: every series, ratio,
// interval and count present and sane.  The smoke run in the VM suite fails
// on any error listed here; speed is never judged.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace agnocast::bench {

std::vector<std::string> report_shape_errors(const nlohmann::ordered_json& report);

// The report as the Markdown tables the README shows.
void print_markdown(const nlohmann::ordered_json& report);

// benchmarks/README.md from one report of both modes ({"icount": report,
// "ordinary": report, ...}, as scripts/bench --write-readme keeps it).
void print_readme(const nlohmann::ordered_json& combined);

}  // namespace agnocast::bench
