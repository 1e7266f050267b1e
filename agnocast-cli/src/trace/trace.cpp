// agnocast-cli trace: record and report, wired into CLI11.
#include "trace/trace.hpp"

#include <CLI/CLI.hpp>
#include <memory>
#include <sstream>

#include "agnocast/naming.hpp"
#include "commands.hpp"
#include "trace/trace_record.hpp"
#include "trace/trace_report.hpp"

namespace agnocast::cli {
namespace {

std::vector<std::string> split_path(const std::string& text) {
  std::vector<std::string> topics;
  std::stringstream in(text);
  std::string topic;
  while (std::getline(in, topic, ',')) {
    if (const std::string problem = topic_name_problem(topic); !problem.empty()) {
      throw InputError("--path: " + problem);
    }
    topics.push_back(topic);
  }
  if (topics.size() < 2) throw InputError("--path needs two topics at least, e.g. --path /a,/b");
  return topics;
}

void set_record_command(CLI::App& trace, Context& context) {
  auto options = std::make_shared<TraceRecordOptions>();
  auto topics = std::make_shared<std::string>();
  CLI::App* record = trace.add_subcommand(
      "record",
      "Record libagnocast's events of every agnocast process and the module's tracepoints as a "
      "Chrome trace-event JSON timeline (ui.perfetto.dev); until SIGINT or --duration");
  record->add_option("--duration", options->duration_s, "Stop after SECONDS")
      ->check(CLI::PositiveNumber);
  record->add_option("-o,--output", options->output,
                     "File to write (default: ./agnocast-trace-<time>.json)");
  record->add_option("--topics", *topics, "Only topics matching this regular expression");
  bind_command(*record, context, {.stream = [&context, options, topics](std::ostream& out) {
    if (!topics->empty()) options->topics = *topics;
    options->json = context.json;
    return trace_record(context.source, *options, out);
  }});
  record->get_option("--json")->description("Print the summary as one JSON object");
}

void set_report_command(CLI::App& trace, Context& context) {
  auto file = std::make_shared<std::string>();
  auto path = std::make_shared<std::string>();
  CLI::App* report = trace.add_subcommand(
      "report",
      "Latency percentiles from a recorded trace: publish -> callback start per topic and node, "
      "callback durations, and along a chain of topics with --path");
  report->add_option("FILE", *file, "A file trace record wrote")->required();
  report->add_option("--path", *path, "Topics of a chain, comma-separated: /a,/b,/c");
  bind_command(*report, context,
               {.build =
                    [file, path] {
                      return trace_report_file(
                          *file, path->empty() ? std::vector<std::string>{} : split_path(*path));
                    },
                .render = trace_report_table});
}

}  // namespace

void set_trace_command(CLI::App& app, Context& context) {
  CLI::App* trace =
      app.add_subcommand("trace", "Record a timeline of publishes and callbacks, and report it");
  trace->require_subcommand(1);
  set_record_command(*trace, context);
  set_report_command(*trace, context);
}

}  // namespace agnocast::cli
