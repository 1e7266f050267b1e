// The command-line front: parses, runs the chosen command, renders its value,
// and turns every failure into the CLI's exit codes (0, 1 runtime, 2 usage).
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>

#include "inspection_source.hpp"

// Only the files that wire options include CLI11, whose header alone costs
// seconds of compile time in every file that includes it.
namespace CLI {
class App;
}

namespace agnocast::cli {

inline constexpr int exit_success = 0;
inline constexpr int exit_runtime_error = 1;
inline constexpr int exit_usage_error = 2;

// A runtime failure the CLI itself detects; the message says what and how to fix it.
class CliError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Input the user gave that cannot be used (a file that is not MCAP, a topic
// that does not exist): a usage error, exit 2.
class InputError : public CliError {
 public:
  using CliError::CliError;
};

// One runnable command: build its value, render it for humans, derive its exit code.
struct Command {
  std::function<nlohmann::json()> build = {};
  std::function<std::string(const nlohmann::json&)> render = {};
  // Exit code from the value (doctor fails when a check fails); nullptr means 0.
  std::function<int(const nlohmann::json&)> exit_code = {};
  // A line for stderr derived from the value (a hint), empty for none; may be nullptr.
  std::function<std::string(const nlohmann::json&)> advice = {};
  // Set for a streaming command (topic echo): it writes its own output as it
  // goes and returns the exit code; the members above are then unused.
  std::function<int(std::ostream& out)> stream = {};
};

// Shared by every subcommand while the command line is parsed.
struct Context {
  InspectionSource& source;
  bool json = false;
  std::optional<Command> chosen;
};

// Gives `sub` its own --json flag and makes it the command that runs when chosen.
void bind_command(CLI::App& sub, Context& context, Command command);
void add_json_flag(CLI::App& app, Context& context);

// The whole CLI; main() passes the real system, tests a fake. Returns the exit code.
int run_cli(int argc, const char* const* argv, InspectionSource& source, std::ostream& out,
            std::ostream& err);

}  // namespace agnocast::cli
