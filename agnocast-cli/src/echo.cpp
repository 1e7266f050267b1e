// agnocast-cli topic echo TOPIC [--count N] [--timeout SEC] [--no-arrays] [--definition] [--json]
#include <CLI/CLI.hpp>

#include "agnocast/cdr.hpp"
#include "agnocast/message_render.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/schema_definition.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

// Polling subscribers are never woken: look this often when nothing is waiting.
constexpr double echo_poll_interval_s = 0.01;

std::string plural(std::size_t n, const char* what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

}  // namespace

int topic_echo(InspectionSource& source, const EchoOptions& options, std::ostream& out) {
  if (options.definition) {
    const Schema schema = source.topic_schema(options.topic);
    std::string text;
    try {
      text = ros2msg_definition(schema);
    } catch (const cdr::Error& error) {
      throw CliError("topic '" + options.topic + "' has no .msg definition: " + error.what());
    }
    if (options.json) {
      out << nlohmann::json{{"topic", options.topic},
                            {"type", schema.types.at(0).name},
                            {"definition", text}}
                 .dump()
          << '\n';
    } else {
      out << text;
    }
    return exit_success;
  }
  const std::unique_ptr<MessageTap> tap = source.subscribe(options.topic);
  const double start = source.now_seconds();
  std::size_t received = 0;
  // Every message comes from another process: render it checked, within its pool.
  auto print = [&](const void* message, std::span<const std::byte> readable) {
    const RenderOptions render{.show_arrays = options.show_arrays, .readable = readable};
    if (options.json) {
      out << render_message_json(message, tap->schema(), render) << '\n';
    } else {
      out << render_message_text(message, tap->schema(), render) << "---\n";
    }
    out.flush();
  };
  while (!options.count || received < *options.count) {
    if (source.stop_requested()) return exit_success;
    if (tap->take(print)) {
      ++received;
      continue;
    }
    if (options.timeout_s && source.now_seconds() - start >= *options.timeout_s) {
      if (!options.count && received > 0) return exit_success;
      const std::string wanted =
          options.count ? std::to_string(*options.count) : std::string("at least 1");
      throw CliError(plural(received, "message") + " on topic '" + options.topic + "' within " +
                     seconds_text(*options.timeout_s) + " s, wanted " + wanted +
                     "; `agnocast-cli topic info " + options.topic +
                     "` shows whether anyone publishes");
    }
    source.sleep_seconds(echo_poll_interval_s);
  }
  return exit_success;
}

void set_topic_echo_command(CLI::App& topic, Context& context) {
  auto options = std::make_shared<EchoOptions>();
  CLI::App* echo = topic.add_subcommand(
      "echo", "Subscribe and print each message, decoded from the schema its publisher registered");
  echo->add_option("TOPIC", options->topic, "Topic name, e.g. /chatter")
      ->required()
      ->check(CLI::Validator(
          [](std::string& name) {
            const std::string problem = topic_name_problem(name);
            return problem.empty() ? service_topic_refusal(name) : problem;
          },
          "TOPIC", "topic name"));
  echo->add_option("--count", options->count, "Stop after N messages (exit 0)")
      ->check(CLI::PositiveNumber);
  echo->add_option("--timeout", options->timeout_s,
                   "Give up after SEC seconds (exit 1) when fewer than --count, or no message, "
                   "arrived")
      ->check(CLI::PositiveNumber);
  echo->add_flag_callback(
      "--no-arrays", [options] { options->show_arrays = false; },
      "Show the length of arrays and sequences instead of their elements");
  echo->add_flag("--definition", options->definition,
                 "Print the type's .msg definition (with every type it uses, as rosbag2 writes "
                 "it) and exit");
  bind_command(*echo, context, {.stream = [&context, options](std::ostream& out) {
    options->json = context.json;
    return topic_echo(context.source, *options, out);
  }});
  echo->get_option("--json")->description("Print one JSON object per message (JSON Lines)");
}

}  // namespace agnocast::cli
