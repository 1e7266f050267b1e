#include "status_file.hpp"

#include "dds_names.hpp"

namespace agnocast_bridge {

nlohmann::json status_body(const BridgeStatus& status) {
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
  return {{"domain_id", status.domain_id}, {"topics", topics}};
}

}  // namespace agnocast_bridge
