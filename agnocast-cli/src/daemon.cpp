// agnocast-cli daemon status: agnocastd's own status file (<agnocast/status.hpp>),
// then agnocast-bridge's and agnocast-foxglove's, each checked against its lock
// so a crashed daemon shows as stopped.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>

#include "agnocast/status.hpp"
#include "agnocast/version.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

// The daemons beside agnocastd: their key in the JSON value and their program.
constexpr std::array<std::pair<const char*, const char*>, 2> other_daemons{{
    {"bridge", "agnocast-bridge"},
    {"foxglove", "agnocast-foxglove"},
}};

// A daemon that crashed leaves "running":true behind. While it runs it holds
// its lock file (beside the status file) exclusively; where that file cannot
// be opened, its pid must be alive and, where /proc tells, be the program
// (whose name /proc cuts to 15 characters).
bool daemon_alive(InspectionSource& source, bool running, pid_t pid, const std::string& lock,
                  const std::string& program) {
  if (!running) return false;
  if (const std::optional<bool> locked = source.exclusively_locked(lock)) return *locked;
  if (!source.process_alive(pid)) return false;
  const std::optional<std::string> comm =
      source.read_file("/proc/" + std::to_string(pid) + "/comm");
  return !comm || comm->rfind(program.substr(0, 15), 0) == 0;
}

// uptime_s in the file is as of its last write; started_at gives it exactly.
std::int64_t uptime_of(InspectionSource& source, std::int64_t started_at) {
  const double uptime = source.unix_time() - static_cast<double>(started_at);
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
  if (status && daemon_alive(source, status->running, status->pid,
                             daemon_lock_path_beside(status_path), "agnocastd")) {
    return {{"running", true},
            {"pid", status->pid},
            {"module_loaded", status->module_version.has_value()},
            {"module_version", status->module_version ? json(*status->module_version) : json()},
            {"uptime_s", uptime_of(source, status->started_at)},
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

json service_status_json(InspectionSource& source, const std::string& status_path,
                         const std::string& program) {
  const json not_running = {{"running", false}, {"pid", nullptr}, {"uptime_s", nullptr}};
  const std::optional<std::string> text = source.read_file(status_path);
  if (!text) return not_running;
  ServiceStatus head;
  try {
    head = service_status_from_json(*text);
  } catch (const StatusFormatError&) {
    return not_running;
  }
  if (!daemon_alive(source, head.running(), head.pid, lock_path_beside(status_path), program)) {
    return not_running;
  }
  json value = json::parse(*text);
  value["uptime_s"] = uptime_of(source, head.started_at);
  return value;
}

json daemon_status_command_json(InspectionSource& source, const DaemonStatusPaths& paths) {
  json value = daemon_status_json(source, paths.agnocastd);
  value["bridge"] = service_status_json(source, paths.bridge, other_daemons[0].second);
  value["foxglove"] = service_status_json(source, paths.foxglove, other_daemons[1].second);
  return value;
}

std::string daemon_status_table(const json& value) {
  const std::string agnocastd =
      key_value_lines(value, {"running", "pid", "module_loaded", "module_version", "uptime_s",
                              "processes_cleaned", "queues_removed", "shm_removed"});
  Table others({{"DAEMON"},
                {"RUNNING"},
                {"STATE"},
                {"PID", Table::Align::right},
                {"UPTIME_S", Table::Align::right},
                {"VERSION"}});
  bool any = false;
  for (const auto& [key, program] : other_daemons) {
    const auto found = value.find(key);
    if (found == value.end()) continue;
    any = true;
    const json& daemon = *found;
    others.add_row({program, cell(daemon.at("running")), cell(daemon.value("state", json())),
                    cell(daemon.at("pid")), cell(daemon.at("uptime_s")),
                    cell(daemon.value("version", json()))});
  }
  return any ? agnocastd + "\n" + others.render() : agnocastd;
}

void set_daemon_command(CLI::App& app, Context& context) {
  CLI::App* daemon = app.add_subcommand("daemon", "The supervisor daemon agnocastd");
  daemon->require_subcommand(1);
  auto paths = std::make_shared<DaemonStatusPaths>();
  CLI::App* status = daemon->add_subcommand(
      "status",
      "Whether agnocastd runs and what it has cleaned up, and whether agnocast-bridge and "
      "agnocast-foxglove run (exit 0 either way)");
  status->add_option("--status-file", paths->agnocastd, "agnocastd's status file")
      ->capture_default_str();
  status->add_option("--bridge-status-file", paths->bridge, "agnocast-bridge's status file")
      ->capture_default_str();
  status->add_option("--foxglove-status-file", paths->foxglove, "agnocast-foxglove's status file")
      ->capture_default_str();
  bind_command(*status, context,
               {[&context, paths] { return daemon_status_command_json(context.source, *paths); },
                daemon_status_table, nullptr,
                [](const json& value) {
                  return value.at("running").get<bool>()
                             ? std::string()
                             : "agnocast-cli: agnocastd is not running: start it with "
                               "`systemctl start agnocastd`";
                }});
}

}  // namespace agnocast::cli
