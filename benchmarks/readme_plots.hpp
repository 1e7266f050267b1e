// The README's plots: one SVG per series that has a scale (sizes, subscribers,
// topics, processes, depth), drawn from the report the tables come from.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace agnocast::bench {

// A mode's plots by the table each follows ("sizes", "fanout", ...): the
// Markdown image line to print after that table.
using PlotLinks = std::map<std::string, std::string>;

// A size as bench::format_size writes it ("64 B", "4 KiB", "16 MiB"), in bytes.
// Throws std::invalid_argument on anything else.
std::size_t size_label_bytes(std::string label);

// Writes into `folder` the plot of every series the combined report
// ({"icount": report, "ordinary": report}) holds, and returns their image
// lines by mode ("icount", "ordinary").  A plot without any of its series is
// not written (an older file of that name is removed) and has no line.  The
// links are relative to the folder's parent (`plots/fanout.svg`), where the
// README is written.
std::map<std::string, PlotLinks> write_readme_plots(const nlohmann::ordered_json& combined,
                                                    const std::filesystem::path& folder);

}  // namespace agnocast::bench
