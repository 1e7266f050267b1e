#include "endpoint_request.hpp"

#include <stdexcept>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/naming.hpp"

namespace agnocast::detail {

EndpointRequest make_endpoint_request(std::string_view node, std::string_view topic, const QoS& qos,
                                      EndpointKind kind, const MessageType& type) {
  validate_topic_name(topic);
  if (qos.depth() < 1 || qos.depth() > depth_max) {
    throw std::invalid_argument("QoS depth " + std::to_string(qos.depth()) +
                                " is out of range: it must be between 1 and " +
                                std::to_string(depth_max));
  }
  EndpointRequest request;
  request.topic = std::string(topic);
  request.node = std::string(node);
  request.depth = static_cast<std::uint32_t>(qos.depth());
  request.transient_local = qos.is_transient_local();
  request.polling = kind == EndpointKind::polling_subscriber;
  request.type_name = std::string(type.name);
  request.type_hash = type.hash;
  request.schema = type.schema;
  return request;
}

}  // namespace agnocast::detail
