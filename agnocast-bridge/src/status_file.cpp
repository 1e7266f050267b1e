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
  nlohmann::json services = nlohmann::json::array();
  for (const auto& service : status.services) {
    const DdsServiceTopics dds_topics = dds_service_topic_names(service.service->name);
    const ServiceTypeNames dds_types = dds_service_type_names(service.service->type);
    services.push_back({{"name", service.service->name},
                        {"type", service.service->type},
                        {"direction", direction_name(service.service->direction)},
                        {"dds_request_topic", dds_topics.request},
                        {"dds_reply_topic", dds_topics.reply},
                        {"dds_request_type", dds_types.dds_request},
                        {"dds_response_type", dds_types.dds_response},
                        {"relayed", service.relayed},
                        {"dropped", service.dropped},
                        {"errors", service.errors}});
  }
  return {{"domain_id", status.domain_id}, {"topics", topics}, {"services", services}};
}

}  // namespace agnocast_bridge
