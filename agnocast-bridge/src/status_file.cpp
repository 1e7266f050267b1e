#include "status_file.hpp"

#include <nlohmann/json.hpp>

#include "agnocast_service/atomic_file.hpp"
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
  agnocast_service::write_file_atomically(path, status_json(status) + "\n");
}

}  // namespace agnocast_bridge
