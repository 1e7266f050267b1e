// What topic hz and topic delay share: one measurement of a topic per window,
// until --count windows or a stop signal, printed as a header and rows or as
// JSON Lines, and the options that say so.
#pragma once

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>

#include "cli.hpp"
#include "inspection_source.hpp"

namespace agnocast::cli {

struct WindowOptions {
  std::string topic;
  double window_s = 1.0;
  std::optional<std::size_t> count;
  bool json = false;  // JSON Lines instead of a header and rows per window
};

using WindowCommand =
    std::function<int(InspectionSource& source, const WindowOptions& options, std::ostream& out)>;

// `topic NAME TOPIC [--window SEC] [--count N] [--json]`, running `run`.
void add_window_command(CLI::App& topic, Context& context, const std::string& name,
                        const std::string& description, WindowCommand run);

// Writes each window measure() returns, until it returns nullopt or
// options.count are written: `header` first, then rows(window) each; with
// options.json one JSON object per line instead.
int stream_windows(const WindowOptions& options, std::ostream& out, const std::string& header,
                   const std::function<std::optional<nlohmann::json>()>& measure,
                   const std::function<std::string(const nlohmann::json&)>& rows);

// x rounded to 1/scale. Dividing by the power of ten gives the double nearest
// the decimal, which JSON then prints as such (multiplying by 1e-6 would not).
double rounded(double x, double scale);
// A number printed with `format`, or "-" for null.
std::string number_or_dash(const nlohmann::json& value, const char* format);

}  // namespace agnocast::cli
