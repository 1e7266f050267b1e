#include "agnocast/status.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <utility>

namespace agnocast {
namespace {

using nlohmann::json;

// Which file is being read, for the error: "agnocastd status file", "status file".
struct Reading {
  std::string file;

  [[noreturn]] void format_error(const std::string& problem) const {
    throw StatusFormatError(file + ": " + problem);
  }

  const json& field(const json& object, const char* key) const {
    const auto found = object.find(key);
    if (found == object.end()) format_error(std::string("\"") + key + "\" is missing");
    return *found;
  }

  bool boolean_field(const json& object, const char* key) const {
    const json& value = field(object, key);
    if (!value.is_boolean()) {
      format_error(std::string("\"") + key + "\" must be true or false, not " + value.dump());
    }
    return value.get<bool>();
  }

  std::string string_field(const json& object, const char* key) const {
    const json& value = field(object, key);
    if (!value.is_string()) {
      format_error(std::string("\"") + key + "\" must be a string, not " + value.dump());
    }
    return value.get<std::string>();
  }

  // An integer in [minimum, the type's maximum]; a fraction or a number out of range is refused.
  template <typename Integer>
  Integer integer_field(const json& object, const char* key,
                        Integer minimum = std::numeric_limits<Integer>::min()) const {
    const json& value = field(object, key);
    const auto fits = [minimum](auto number) {
      return std::in_range<Integer>(number) && std::cmp_greater_equal(number, minimum);
    };
    if (value.is_number_unsigned() ? fits(value.get<std::uint64_t>())
                                   : value.is_number_integer() && fits(value.get<std::int64_t>())) {
      return value.get<Integer>();
    }
    format_error(std::string("\"") + key + "\" must be an integer from " + std::to_string(minimum) +
                 " to " + std::to_string(std::numeric_limits<Integer>::max()) + ", not " +
                 value.dump());
  }

  // The text as a JSON object.
  json object(std::string_view text) const {
    json parsed = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (parsed.is_discarded()) format_error("not JSON");
    if (!parsed.is_object()) format_error("not a JSON object");
    return parsed;
  }
};

constexpr std::array<std::pair<ServiceState, std::string_view>, 3> state_names{{
    {ServiceState::running, "running"},
    {ServiceState::stopping, "stopping"},
    {ServiceState::stopped, "stopped"},
}};

}  // namespace

std::string daemon_lock_path_beside(std::string_view status_path) {
  const std::filesystem::path lock_name = std::filesystem::path(daemon_lock_path).filename();
  return (std::filesystem::path(status_path).parent_path() / lock_name).string();
}

std::string lock_path_beside(std::string_view status_path) {
  return std::filesystem::path(status_path).replace_extension(".lock").string();
}

std::string to_json(const DaemonStatus& status) {
  const json object = {
      {"running", status.running},
      {"pid", status.pid},
      {"module_loaded", status.module_version.has_value()},
      {"module_version", status.module_version ? json(*status.module_version) : json(nullptr)},
      {"uptime_s", status.uptime_s},
      {"started_at", status.started_at},
      {"processes_cleaned", status.counters.processes_cleaned},
      {"queues_removed", status.counters.queues_removed},
      {"shm_removed", status.counters.shm_removed},
  };
  return object.dump() + "\n";
}

DaemonStatus daemon_status_from_json(std::string_view text) {
  const Reading reading{"agnocastd status file"};
  const json object = reading.object(text);
  DaemonStatus status;
  status.running = reading.boolean_field(object, "running");
  status.pid = reading.integer_field<pid_t>(object, "pid", 1);
  const bool module_loaded = reading.boolean_field(object, "module_loaded");
  const json& version = reading.field(object, "module_version");
  if (module_loaded != version.is_string() || !(version.is_string() || version.is_null())) {
    reading.format_error(
        "\"module_version\" must be a string when \"module_loaded\" is true and null "
        "when it is false, not " +
        version.dump());
  }
  if (module_loaded) status.module_version = version.get<std::string>();
  status.uptime_s = reading.integer_field<std::uint64_t>(object, "uptime_s");
  status.started_at = reading.integer_field<std::int64_t>(object, "started_at");
  status.counters.processes_cleaned =
      reading.integer_field<std::uint64_t>(object, "processes_cleaned");
  status.counters.queues_removed = reading.integer_field<std::uint64_t>(object, "queues_removed");
  status.counters.shm_removed = reading.integer_field<std::uint64_t>(object, "shm_removed");
  return status;
}

std::string_view state_name(ServiceState state) {
  for (const auto& [value, name] : state_names) {
    if (value == state) return name;
  }
  return "unknown";
}

std::string to_json(const ServiceStatus& head) {
  // Ordered: every status file starts with these, in this order.
  const nlohmann::ordered_json object = {
      {"program", head.program},   {"pid", head.pid},
      {"version", head.version},   {"state", state_name(head.state)},
      {"running", head.running()}, {"started_at", head.started_at},
      {"uptime_s", head.uptime_s}, {"written_at", head.written_at},
  };
  return object.dump() + "\n";
}

ServiceStatus service_status_from_json(std::string_view text) {
  const Reading reading{"status file"};
  const json object = reading.object(text);
  ServiceStatus head;
  head.program = reading.string_field(object, "program");
  head.pid = reading.integer_field<pid_t>(object, "pid", 1);
  head.version = reading.string_field(object, "version");
  const std::string state = reading.string_field(object, "state");
  const auto named = std::find_if(state_names.begin(), state_names.end(),
                                  [&state](const auto& entry) { return entry.second == state; });
  if (named == state_names.end()) {
    reading.format_error("\"state\" must be \"running\", \"stopping\" or \"stopped\", not \"" +
                         state + "\"");
  }
  head.state = named->first;
  if (reading.boolean_field(object, "running") != head.running()) {
    reading.format_error(
        "\"running\" must be false when \"state\" is \"stopped\" and true otherwise");
  }
  head.started_at = reading.integer_field<std::int64_t>(object, "started_at");
  head.uptime_s = reading.integer_field<std::uint64_t>(object, "uptime_s");
  head.written_at = reading.integer_field<std::int64_t>(object, "written_at");
  return head;
}

}  // namespace agnocast
