// The status JSON agnocast-cli reads (format in <agnocastd/status_file.hpp>).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "counters.hpp"

namespace agnocastd {

struct Status {
  bool running = true;
  pid_t pid = 0;
  std::optional<std::string> module_version;  // nullopt: module not loaded
  std::uint64_t uptime_s = 0;
  std::int64_t started_at = 0;  // Unix seconds
  Counters counters;
};

nlohmann::json status_json(const Status& status);

// Replaces path atomically (temporary file + rename) with mode 0644, creating
// its directory (0755) if needed; throws std::system_error.
void write_status_file(const std::string& path, const nlohmann::json& status);

}  // namespace agnocastd
