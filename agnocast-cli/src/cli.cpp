#include "cli.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <exception>
#include <string_view>

#include "bag/bag.hpp"
#include "commands.hpp"
#include "trace/trace.hpp"

namespace agnocast::cli {
namespace {

// With --json a failure still prints exactly one object on stdout, so scripts
// can always parse it; the message goes to stderr as well for people.
int fail(int code, const std::string& message, bool json, std::ostream& out, std::ostream& err) {
  err << "agnocast-cli: " << message << '\n';
  if (json) out << nlohmann::json{{"error", message}, {"exit_code", code}}.dump() << '\n';
  return code;
}

// --json is known before parsing finishes, so usage errors honour it too.
bool wants_json(int argc, const char* const* argv) {
  return std::any_of(argv + 1, argv + argc,
                     [](const char* arg) { return std::string_view(arg) == "--json"; });
}

int run_chosen(const Command& command, bool json, std::ostream& out, std::ostream& err) {
  if (command.stream) return command.stream(out);
  const nlohmann::json value = command.build();
  if (json) {
    out << value.dump() << '\n';
  } else {
    out << command.render(value);
  }
  if (command.advice) {
    if (const std::string advice = command.advice(value); !advice.empty()) err << advice << '\n';
  }
  return command.exit_code ? command.exit_code(value) : exit_success;
}

std::string command_names(const std::vector<CLI::App*>& commands) {
  std::string names;
  for (const CLI::App* command : commands) {
    if (!names.empty()) names += ", ";
    names += command->get_name();
  }
  return names;
}

// For a failed parse: the first word that is no command of the command it
// follows, or a command given without the command it needs, with the valid
// ones; empty when the commands are right (an option or argument is wrong).
std::string command_problem(CLI::App& app, int argc, const char* const* argv) {
  CLI::App* current = &app;
  std::string path = app.get_name();
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.starts_with("-")) continue;
    const std::vector<CLI::App*> commands = current->get_subcommands({});
    if (commands.empty()) return {};  // a leaf: the rest are its arguments
    const auto match = std::find_if(commands.begin(), commands.end(), [&](const CLI::App* command) {
      return command->check_name(word);
    });
    if (match == commands.end()) {
      return "unknown command '" + word + "' for '" + path +
             "'; valid commands: " + command_names(commands);
    }
    current = *match;
    path += " " + current->get_name();
  }
  const std::vector<CLI::App*> commands = current->get_subcommands({});
  if (commands.empty()) return {};
  return "'" + path + "' needs a command: " + command_names(commands);
}

// `agnocast-cli --version` is the `version` command: the flag becomes the
// command's name when it comes before any command.
std::vector<const char*> with_version_flag_as_command(int argc, const char* const* argv) {
  std::vector<const char*> args(argv, argv + argc);
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string_view arg = args[i];
    if (arg == "--version") {
      args[i] = "version";
      break;
    }
    if (!arg.starts_with("-")) break;  // a command: --version is its option, if any
  }
  return args;
}

}  // namespace

void add_json_flag(CLI::App& app, Context& context) {
  app.add_flag("--json", context.json, "Print exactly one JSON object instead of a table");
}

void bind_command(CLI::App& sub, Context& context, Command command) {
  add_json_flag(sub, context);
  sub.callback([&context, command = std::move(command)] { context.chosen = command; });
}

int run_cli(int argc, const char* const* argv_given, InspectionSource& source, std::ostream& out,
            std::ostream& err) {
  const std::vector<const char*> args = with_version_flag_as_command(argc, argv_given);
  const char* const* argv = args.data();
  Context context{source, false, std::nullopt};
  CLI::App app{"agnocast-cli: inspect agnocast topics, services, queues, nodes and the daemon",
               "agnocast-cli"};
  app.require_subcommand(1);
  add_json_flag(app, context);
  set_topic_command(app, context);
  set_service_command(app, context);
  set_queue_command(app, context);
  set_node_command(app, context);
  set_process_command(app, context);
  set_daemon_command(app, context);
  set_doctor_command(app, context);
  set_policy_command(app, context);
  set_version_command(app, context);
  set_bag_command(app, context);
  set_trace_command(app, context);
  // Shown in --help; run_cli turns it into the version command before parsing.
  app.add_flag("--version")->description("Same as the version command");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help
    return app.exit(e, out, err);
  } catch (const CLI::ParseError& e) {
    const std::string unknown = command_problem(app, argc, argv);
    return fail(exit_usage_error,
                (unknown.empty() ? e.what() : unknown) + std::string("; see --help"),
                wants_json(argc, argv), out, err);
  }
  if (!context.chosen) {
    return fail(exit_usage_error, "no command given; see --help", context.json, out, err);
  }

  try {
    return run_chosen(*context.chosen, context.json, out, err);
  } catch (const InputError& e) {
    return fail(exit_usage_error, e.what(), context.json, out, err);
  } catch (const std::exception& e) {
    // ModuleNotLoaded and the CLI's own errors already name the fix.
    return fail(exit_runtime_error, e.what(), context.json, out, err);
  }
}

}  // namespace agnocast::cli
