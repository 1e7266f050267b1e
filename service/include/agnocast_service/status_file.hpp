// A daemon's status file: the head every agnocast daemon writes
// (<agnocast/status.hpp>'s ServiceStatus, its fields first and in order),
// then the daemon's own fields, replaced atomically, mode 0644. ServiceLoop
// writes it; agnocast-cli daemon status reads it.
//
//   agnocast_service::write_status_file("/run/agnocast/x.json", head, {{"topics", 3}});
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "agnocast/status.hpp"

namespace agnocast_service {

// The file's text: the head, then each field of body (an object) that the
// head does not have, then a newline.
std::string status_file_text(const agnocast::ServiceStatus& head, const nlohmann::json& body);

// Replaces path with status_file_text() (write_file_atomically); throws
// std::system_error when it cannot.
void write_status_file(const std::string& path, const agnocast::ServiceStatus& head,
                       const nlohmann::json& body);

}  // namespace agnocast_service
