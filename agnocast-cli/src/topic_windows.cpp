#include "topic_windows.hpp"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>

#include "agnocast/naming.hpp"

namespace agnocast::cli {

void add_window_command(CLI::App& topic, Context& context, const std::string& name,
                        const std::string& description, WindowCommand run) {
  auto options = std::make_shared<WindowOptions>();
  CLI::App* sub = topic.add_subcommand(name, description);
  sub->add_option("TOPIC", options->topic, "Topic name, e.g. /chatter")
      ->required()
      ->check(CLI::Validator([](std::string& topic_name) { return topic_name_problem(topic_name); },
                             "TOPIC", "topic name"));
  sub->add_option("--window", options->window_s, "Seconds per window")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sub->add_option("--count", options->count, "Stop after N windows (exit 0)")
      ->check(CLI::PositiveNumber);
  bind_command(*sub, context, {.stream = [&context, options, run](std::ostream& out) {
    options->json = context.json;
    return run(context.source, *options, out);
  }});
  sub->get_option("--json")->description("Print one JSON object per window (JSON Lines)");
}

int stream_windows(const WindowOptions& options, std::ostream& out, const std::string& header,
                   const std::function<std::optional<nlohmann::json>()>& measure,
                   const std::function<std::string(const nlohmann::json&)>& rows) {
  if (!options.json) out << header << std::flush;
  for (std::size_t windows = 0; !options.count || windows < *options.count; ++windows) {
    const std::optional<nlohmann::json> window = measure();
    if (!window) break;
    out << (options.json ? window->dump() + "\n" : rows(*window)) << std::flush;
  }
  return exit_success;
}

double rounded(double x, double scale) { return std::round(x * scale) / scale; }

std::string number_or_dash(const nlohmann::json& value, const char* format) {
  if (value.is_null()) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, value.get<double>());
  return text;
}

}  // namespace agnocast::cli
