// agnocast-cli daemon status: agnocastd's own status file (<agnocast/status.hpp>),
// checked against its lock so a crashed daemon shows as stopped.
#include <algorithm>
#include <cstdint>

#include "agnocast/status.hpp"
#include "agnocast/version.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

// A daemon that crashed leaves "running":true behind. While it runs it holds
// its lock file (beside the status file) exclusively; where that file cannot
// be opened, its pid must be alive and, where /proc tells, be agnocastd.
bool daemon_alive(InspectionSource& source, const DaemonStatus& status,
                  const std::string& status_path) {
  if (!status.running) return false;
  const std::string lock = daemon_lock_path_beside(status_path);
  if (const std::optional<bool> locked = source.exclusively_locked(lock)) return *locked;
  const pid_t pid = status.pid;
  if (!source.process_alive(pid)) return false;
  const std::optional<std::string> comm =
      source.read_file("/proc/" + std::to_string(pid) + "/comm");
  return !comm || comm->rfind("agnocastd", 0) == 0;
}

// uptime_s in the file is as of its last write; started_at gives it exactly.
std::int64_t uptime_of(InspectionSource& source, const DaemonStatus& status) {
  const double uptime = source.unix_time() - static_cast<double>(status.started_at);
  return static_cast<std::int64_t>(std::max(0.0, uptime));
}

}  // namespace

DaemonStatusRead read_daemon_status(InspectionSource& source, const std::string& status_path) {
  const std::optional<std::string> text = source.read_file(status_path);
  if (!text) return {};
  try {
    return {daemon_status_from_json(*text), {}};
  } catch (const StatusFormatError& error) {
    return {std::nullopt, status_path + ": " + error.what()};
  }
}

json daemon_status_json(InspectionSource& source, const std::string& status_path) {
  const std::optional<DaemonStatus> status = read_daemon_status(source, status_path).status;
  if (status && daemon_alive(source, *status, status_path)) {
    return {{"running", true},
            {"pid", status->pid},
            {"module_loaded", status->module_version.has_value()},
            {"module_version", status->module_version ? json(*status->module_version) : json()},
            {"uptime_s", uptime_of(source, *status)},
            {"processes_cleaned", status->counters.processes_cleaned},
            {"queues_removed", status->counters.queues_removed},
            {"shm_removed", status->counters.shm_removed}};
  }
  // No daemon: what it would report about the module, the CLI sees for itself.
  const std::optional<Version> module = source.module_version();
  return {{"running", false},
          {"pid", nullptr},
          {"module_loaded", module.has_value()},
          {"module_version", module ? json(module->to_string()) : json(nullptr)},
          {"uptime_s", nullptr},
          {"processes_cleaned", nullptr},
          {"queues_removed", nullptr},
          {"shm_removed", nullptr}};
}

std::string daemon_status_table(const json& value) {
  return key_value_lines(value, {"running", "pid", "module_loaded", "module_version", "uptime_s",
                                 "processes_cleaned", "queues_removed", "shm_removed"});
}

void set_daemon_command(CLI::App& app, Context& context) {
  CLI::App* daemon = app.add_subcommand("daemon", "The supervisor daemon agnocastd");
  daemon->require_subcommand(1);
  auto status_path = std::make_shared<std::string>(daemon_status_path);
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
