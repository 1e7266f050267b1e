#include "status_file.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <system_error>

#include "dds_names.hpp"

namespace agnocast_bridge {

std::string status_json(const BridgeStatus& status) {
  nlohmann::json topics = nlohmann::json::array();
  for (const auto& topic : status.topics) {
    topics.push_back({{"name", topic.topic->name},
                      {"type", topic.topic->type},
                      {"direction", direction_name(topic.topic->direction)},
                      {"dds_topic", dds_topic_name(topic.topic->name)},
                      {"dds_type", dds_type_name(topic.topic->type)},
                      {"relayed", topic.relayed},
                      {"dropped", topic.dropped},
                      {"errors", topic.errors}});
  }
  const nlohmann::json document = {
      {"running", status.running},     {"pid", status.pid},
      {"domain_id", status.domain_id}, {"started_at", status.started_at},
      {"uptime_s", status.uptime_s},   {"topics", topics}};
  return document.dump();
}

void write_status_file(const std::string& path, const BridgeStatus& status) {
  const std::filesystem::path target(path);
  if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path());
  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::trunc);
    file << status_json(status) << '\n';
    if (!file.flush()) {
      throw std::system_error(errno, std::generic_category(), "cannot write " + temporary);
    }
  }
  ::chmod(temporary.c_str(), 0644);
  std::filesystem::rename(temporary, target);
}

}  // namespace agnocast_bridge
