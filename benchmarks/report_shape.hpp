// What a report must hold whatever the machine's speed: every series, ratio,
// interval and count present and sane.  The smoke run in the VM suite fails
// on any error listed here; speed is never judged.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "readme_plots.hpp"

namespace agnocast::bench {

std::vector<std::string> report_shape_errors(const nlohmann::ordered_json& report);

// The report as the Markdown tables the README shows, each followed by its
// plot's image line in `plots`, if any.
void print_markdown(const nlohmann::ordered_json& report, const PlotLinks& plots = {});

// benchmarks/README.md from one report of both modes ({"icount": report,
// "ordinary": report, ...}, as scripts/bench --write-readme keeps it), with
// each mode's plots (write_readme_plots).
void print_readme(const nlohmann::ordered_json& combined,
                  const std::map<std::string, PlotLinks>& plots = {});

// The README's section on what the module's trace events and libagnocast's
// LTTng-UST call sites cost while nobody traces, from the combined report's
// "tracing_cost" (the same series as built, with the module built without
// its events, and with libagnocast built without its provider as well);
// nothing when it has none.  A run missing from it shows as "—".
void print_tracing_cost(const nlohmann::ordered_json& combined);

}  // namespace agnocast::bench
