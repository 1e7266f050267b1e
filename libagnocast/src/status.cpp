#include "agnocast/status.hpp"

#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <utility>

namespace agnocast {
namespace {

using nlohmann::json;

[[noreturn]] void format_error(const std::string& problem) {
  throw StatusFormatError("agnocastd status file: " + problem);
}

const json& field(const json& object, const char* key) {
  const auto found = object.find(key);
  if (found == object.end()) format_error(std::string("\"") + key + "\" is missing");
  return *found;
}

bool boolean_field(const json& object, const char* key) {
  const json& value = field(object, key);
  if (!value.is_boolean()) {
    format_error(std::string("\"") + key + "\" must be true or false, not " + value.dump());
  }
  return value.get<bool>();
}

// An integer in [minimum, the type's maximum]; a fraction or a number out of range is refused.
template <typename Integer>
Integer integer_field(const json& object, const char* key,
                      Integer minimum = std::numeric_limits<Integer>::min()) {
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

}  // namespace

std::string daemon_lock_path_beside(std::string_view status_path) {
  const std::filesystem::path lock_name = std::filesystem::path(daemon_lock_path).filename();
  return (std::filesystem::path(status_path).parent_path() / lock_name).string();
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
  const json object = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (object.is_discarded()) format_error("not JSON");
  if (!object.is_object()) format_error("not a JSON object");
  DaemonStatus status;
  status.running = boolean_field(object, "running");
  status.pid = integer_field<pid_t>(object, "pid", 1);
  const bool module_loaded = boolean_field(object, "module_loaded");
  const json& version = field(object, "module_version");
  if (module_loaded != version.is_string() || !(version.is_string() || version.is_null())) {
    format_error(
        "\"module_version\" must be a string when \"module_loaded\" is true and null "
        "when it is false, not " +
        version.dump());
  }
  if (module_loaded) status.module_version = version.get<std::string>();
  status.uptime_s = integer_field<std::uint64_t>(object, "uptime_s");
  status.started_at = integer_field<std::int64_t>(object, "started_at");
  status.counters.processes_cleaned = integer_field<std::uint64_t>(object, "processes_cleaned");
  status.counters.queues_removed = integer_field<std::uint64_t>(object, "queues_removed");
  status.counters.shm_removed = integer_field<std::uint64_t>(object, "shm_removed");
  return status;
}

}  // namespace agnocast
