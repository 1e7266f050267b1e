#include "endpoints/endpoint_request.hpp"

#include <stdexcept>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/limits.hpp"
#include "agnocast/naming.hpp"

namespace agnocast::detail {

EndpointRequest make_endpoint_request(std::string_view node, std::string_view topic, const QoS& qos,
                                      EndpointKind kind, const MessageType& type,
                                      TopicUse use) {
  validate_topic_name(topic);
  if (use == TopicUse::application && is_service_topic(topic)) {
    throw std::invalid_argument("topic name '" + std::string(topic) +
                                "' is reserved: topics under " +
                                std::string(service_request_prefix) + " and " +
                                std::string(service_reply_prefix) +
                                " carry services; create a service or client instead");
  }
  if (qos.depth() < qos_depth_min || qos.depth() > qos_depth_max) {
    throw std::invalid_argument(
        "QoS depth " + std::to_string(qos.depth()) + " is out of range: it must be between " +
        std::to_string(qos_depth_min) + " and " + std::to_string(qos_depth_max));
  }
  if (type.name.size() > type_name_max) {
    throw std::invalid_argument("message type name '" + std::string(type.name) +
                                "' is too long: at most " + std::to_string(type_name_max) +
                                " characters");
  }
  EndpointRequest request;
  request.topic = std::string(topic);
  request.node = std::string(node);
  request.depth = static_cast<std::uint32_t>(qos.depth());
  request.transient_local = qos.is_transient_local();
  request.polling = kind == EndpointKind::polling_subscriber;
  request.wake_once = kind == EndpointKind::callback_subscriber;
  request.type_name = std::string(type.name);
  request.type_hash = type.hash;
  request.schema = type.schema;
  return request;
}

}  // namespace agnocast::detail
