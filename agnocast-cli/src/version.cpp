// agnocast-cli version: the CLI's, the library's and the loaded module's versions.
#include "agnocast/version.hpp"

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {

nlohmann::json version_json(InspectionSource& source) {
  const std::optional<Version> module = source.module_version();
  return {{"cli", AGNOCAST_CLI_VERSION},
          {"library", std::string(library_version_string)},
          {"module", module ? nlohmann::json(module->to_string()) : nlohmann::json(nullptr)}};
}

std::string version_table(const nlohmann::json& value) {
  return key_value_lines(value, {"cli", "library", "module"});
}

void set_version_command(CLI::App& app, Context& context) {
  CLI::App* version = app.add_subcommand("version", "Versions of the CLI, library and module");
  bind_command(*version, context,
               {[&context] { return version_json(context.source); }, version_table});
}

}  // namespace agnocast::cli
