#include "agnocast_service/status_file.hpp"

#include "agnocast_service/atomic_file.hpp"

namespace agnocast_service {

std::string status_file_text(const agnocast::ServiceStatus& head, const nlohmann::json& body) {
  auto file = nlohmann::ordered_json::parse(agnocast::to_json(head));
  for (const auto& [key, value] : body.items()) {
    if (!file.contains(key)) file[key] = value;
  }
  return file.dump() + "\n";
}

void write_status_file(const std::string& path, const agnocast::ServiceStatus& head,
                       const nlohmann::json& body) {
  write_file_atomically(path, status_file_text(head, body));
}

}  // namespace agnocast_service
