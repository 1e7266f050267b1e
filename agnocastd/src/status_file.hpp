// Writing the status file agnocast-cli reads (its format: <agnocast/status.hpp>).
#pragma once

#include <string>

namespace agnocastd {

// Replaces path atomically (temporary file + rename) with text, mode 0644,
// creating its directory (0755) if needed; throws std::system_error.
void write_status_file(const std::string& path, const std::string& text);

}  // namespace agnocastd
