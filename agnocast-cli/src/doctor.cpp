// agnocast-cli doctor: the checks a working installation passes, each with a
// detail that says what is wrong and how to fix it. Exit 1 if any fails.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstring>
#include <sstream>

#include "agnocast/inspect.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/status.hpp"
#include "agnocast/version.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

constexpr const char* start_daemon = "start it with `systemctl start agnocastd`";
// Linux's defaults; a smaller limit means someone lowered it and queues will fail.
constexpr long msg_max_minimum = 10;
constexpr long queues_max_minimum = 256;

json check(const std::string& name, bool ok, const std::string& detail) {
  return {{"name", name}, {"ok", ok}, {"detail", detail}};
}

std::optional<Version> try_module_version(InspectionSource& source, std::string& problem) {
  try {
    return source.module_version();
  } catch (const std::exception& e) {
    problem = e.what();
    return std::nullopt;
  }
}

json module_check(InspectionSource& source) {
  if (source.path_exists(module_sysfs_directory) || source.path_exists(device_path)) {
    return check("module", true, "agnocast.ko is loaded");
  }
  return check("module", false, std::string("agnocast.ko is not loaded: ") + start_daemon);
}

json device_check(InspectionSource& source) {
  if (!source.path_exists(device_path)) {
    return check("device", false,
                 std::string(device_path) + " is missing: the module creates it; " + start_daemon);
  }
  if (const int error = source.path_access(device_path, R_OK | W_OK); error != 0) {
    return check("device", false,
                 std::string(device_path) + " is not readable and writable by this user (" +
                     std::strerror(error) + "): check the mode agnocastd gives it, or use root");
  }
  return check("device", true, std::string(device_path) + " is present and accessible");
}

json version_check(InspectionSource& source) {
  const std::string library = library_version.to_string();
  std::string problem;
  const std::optional<Version> module = try_module_version(source, problem);
  if (!module) {
    return check("version", false,
                 "cannot read the module's version" +
                     (problem.empty() ? ": the module is not loaded" : ": " + problem));
  }
  const std::string both = "module " + module->to_string() + ", library " + library;
  if (!is_compatible(*module)) {
    return check("version", false,
                 both + ": major.minor differ; install a module and library of one release");
  }
  return check("version", true, both + ": compatible");
}

json mqueue_mount_check(InspectionSource& source) {
  const std::string directory(mqueue_directory);
  std::istringstream mounts(source.read_file("/proc/mounts").value_or(""));
  std::string line;
  while (std::getline(mounts, line)) {
    std::istringstream fields(line);
    std::string device, mount_point, type;
    fields >> device >> mount_point >> type;
    if (mount_point == directory && type == "mqueue") {
      return check("mqueue_mount", true, "mqueue filesystem mounted at " + directory);
    }
  }
  return check("mqueue_mount", false,
               "no mqueue filesystem at " + directory + ": agnocastd mounts it, or `mkdir -p " +
                   directory + " && mount -t mqueue mqueue " + directory + "`");
}

std::optional<long> read_number(InspectionSource& source, const std::string& path) {
  const std::optional<std::string> text = source.read_file(path);
  if (!text) return std::nullopt;
  try {
    return std::stol(*text);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

json mqueue_limits_check(InspectionSource& source) {
  const auto msg_max = read_number(source, "/proc/sys/fs/mqueue/msg_max");
  const auto queues_max = read_number(source, "/proc/sys/fs/mqueue/queues_max");
  if (!msg_max || !queues_max) {
    return check("mqueue_limits", false,
                 "cannot read /proc/sys/fs/mqueue/msg_max and queues_max: is /proc mounted?");
  }
  const long in_use = static_cast<long>(source.queue_files().size());
  const std::string numbers = "fs.mqueue.msg_max=" + std::to_string(*msg_max) +
                              ", fs.mqueue.queues_max=" + std::to_string(*queues_max) + ", " +
                              std::to_string(in_use) + " queues in use";
  if (*msg_max < msg_max_minimum || *queues_max < queues_max_minimum) {
    return check("mqueue_limits", false,
                 numbers + ": below Linux's defaults (" + std::to_string(msg_max_minimum) + ", " +
                     std::to_string(queues_max_minimum) +
                     "); raise them with sysctl (agnocast's sysctl.d drop-in does)");
  }
  if (in_use >= *queues_max) {
    return check("mqueue_limits", false,
                 numbers +
                     ": no queue left; raise fs.mqueue.queues_max or remove stale queues "
                     "(`agnocast-cli queue list` shows them)");
  }
  return check("mqueue_limits", true, numbers);
}

json daemon_check(InspectionSource& source, const std::string& status_path) {
  const json status = daemon_status_json(source, status_path);
  if (!status.at("running").get<bool>()) {
    const std::string problem = read_daemon_status(source, status_path).problem;
    return check("daemon", false,
                 "agnocastd is not running" + (problem.empty() ? "" : " (" + problem + ")") + ": " +
                     start_daemon);
  }
  return check("daemon", true, "agnocastd is running as pid " + status.at("pid").dump());
}

}  // namespace

json doctor_json(InspectionSource& source, const std::string& daemon_status_path) {
  return {{"checks",
           {module_check(source), device_check(source), version_check(source),
            mqueue_mount_check(source), mqueue_limits_check(source),
            daemon_check(source, daemon_status_path)}}};
}

std::string doctor_table(const json& value) {
  Table table({{"CHECK"}, {"RESULT"}, {"DETAIL"}});
  for (const json& c : value.at("checks")) {
    table.add_row(
        {cell(c.at("name")), c.at("ok").get<bool>() ? "ok" : "FAIL", cell(c.at("detail"))});
  }
  return table.render();
}

void set_doctor_command(CLI::App& app, Context& context) {
  auto status_path = std::make_shared<std::string>(daemon_status_path);
  CLI::App* doctor = app.add_subcommand(
      "doctor", "Check the module, device, versions, mqueue and daemon (exit 1 if any fails)");
  doctor->add_option("--status-file", *status_path, "agnocastd's status file")
      ->capture_default_str();
  bind_command(
      *doctor, context,
      {[&context, status_path] { return doctor_json(context.source, *status_path); }, doctor_table,
       [](const json& value) {
         for (const json& c : value.at("checks")) {
           if (!c.at("ok").get<bool>()) return exit_runtime_error;
         }
         return exit_success;
       }});
}

}  // namespace agnocast::cli
