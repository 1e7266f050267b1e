// What recording costs: agnocast-cli bag record (default zstd) while one
// publisher sends a 4 MiB PointCloud2 at 20 Hz, then 64 B at 1 kHz — the
// recorder's CPU time per recorded message and what did not reach the file.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace agnocast::bench {

// `cli` is the agnocast-cli program; with `smoke`, a few messages only.
nlohmann::json run_recording(const std::string& cli, bool smoke);

}  // namespace agnocast::bench
