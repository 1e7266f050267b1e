// agnocast-cli daemon status: agnocastd's own status file (its path comes from
// agnocastd's header), checked against its lock so a crashed daemon shows as stopped.
#include <algorithm>
#include <cstdint>
#include <filesystem>

#include "agnocast/version.hpp"
#include "agnocastd/status_file.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

const std::vector<std::string> counter_keys = {"uptime_s", "processes_cleaned", "queues_removed",
                                               "shm_removed"};

std::optional<json> read_status(InspectionSource& source, const std::string& path) {
  const std::optional<std::string> text = source.read_file(path);
  if (!text) return std::nullopt;
  json status = json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (!status.is_object() || !status.contains("pid") || !status["pid"].is_number_integer() ||
      !status.contains("running") || !status["running"].is_boolean()) {
    return std::nullopt;
  }
  return status;
}

// A daemon that crashed leaves "running":true behind. While it runs it holds
// its lock file (beside the status file) exclusively; where that file cannot
// be opened, its pid must be alive and, where /proc tells, be agnocastd.
bool daemon_alive(InspectionSource& source, const json& status, const std::string& status_path) {
  if (!status.at("running").get<bool>()) return false;
  const std::string lock = (std::filesystem::path(status_path).parent_path() /
                            std::filesystem::path(std::string(agnocastd::lock_path)).filename())
                               .string();
  if (const std::optional<bool> locked = source.exclusively_locked(lock)) return *locked;
  const pid_t pid = status.at("pid").get<pid_t>();
  if (!source.process_alive(pid)) return false;
  const std::optional<std::string> comm =
      source.read_file("/proc/" + std::to_string(pid) + "/comm");
  return !comm || comm->rfind("agnocastd", 0) == 0;
}

// uptime_s in the file is as of its last write; started_at gives it exactly.
json uptime_of(InspectionSource& source, const json& status) {
  if (status.contains("started_at") && status["started_at"].is_number()) {
    const double uptime = source.unix_time() - status["started_at"].get<double>();
    return static_cast<std::int64_t>(std::max(0.0, uptime));
  }
  return status.value("uptime_s", json(nullptr));
}

}  // namespace

json daemon_status_json(InspectionSource& source, const std::string& status_path) {
  const std::optional<json> status = read_status(source, status_path);
  if (status && daemon_alive(source, *status, status_path)) {
    json value = {{"running", true},
                  {"pid", status->at("pid")},
                  {"module_loaded", status->value("module_loaded", json(nullptr))},
                  {"module_version", status->value("module_version", json(nullptr))}};
    for (const std::string& key : counter_keys) value[key] = status->value(key, json(nullptr));
    value["uptime_s"] = uptime_of(source, *status);
    return value;
  }
  // No daemon: what it would report about the module, the CLI sees for itself.
  const std::optional<Version> module = source.module_version();
  json value = {{"running", false},
                {"pid", nullptr},
                {"module_loaded", module.has_value()},
                {"module_version", module ? json(module->to_string()) : json(nullptr)}};
  for (const std::string& key : counter_keys) value[key] = nullptr;
  return value;
}

std::string daemon_status_table(const json& value) {
  return key_value_lines(value, {"running", "pid", "module_loaded", "module_version", "uptime_s",
                                 "processes_cleaned", "queues_removed", "shm_removed"});
}

void set_daemon_command(CLI::App& app, Context& context) {
  CLI::App* daemon = app.add_subcommand("daemon", "The supervisor daemon agnocastd");
  daemon->require_subcommand(1);
  auto status_path = std::make_shared<std::string>(agnocastd::status_path);
  CLI::App* status = daemon->add_subcommand(
      "status", "Whether agnocastd runs, and what it has cleaned up (exit 0 either way)");
  status->add_option("--status-file", *status_path, "agnocastd's status file")
      ->capture_default_str();
  bind_command(
      *status, context,
      {[&context, status_path] { return daemon_status_json(context.source, *status_path); },
       daemon_status_table, nullptr,
       [](const json& value) {
         return value.at("running").get<bool>()
                    ? std::string()
                    : "agnocast-cli: agnocastd is not running: start it with "
                      "`systemctl start agnocastd`";
       }});
}

}  // namespace agnocast::cli
