// A service's two parts known from their schemas alone: the request and the
// response type, as the topics that carry the service register them. What a
// tool that calls a service it was not compiled for starts from
// (agnocast-cli service call), and what a binding hands to SchemaClient and
// SchemaService from its own classes (Python).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "agnocast/message_traits.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/schema_topic.hpp"

namespace agnocast {

struct ServiceTypes {
  SchemaTopic request;   // on service_request_topic(): "pkg/srv/Name_Request"
  SchemaTopic response;  // on service_reply_topic(): "pkg/srv/Name_Response"
};

// The service type both parts belong to: "pkg/srv/Name" from
// "pkg/srv/Name_Request" and "pkg/srv/Name_Response"; empty when they are
// not the two parts of one service type.
std::string service_type_name(const ServiceTypes& types);

// "pkg/srv/Name" as written, or "pkg/Name" completed to it; empty when the
// text is no service type name of either form.
std::string normalized_service_type(std::string_view type);

// The types the endpoints of the service's two topics registered with the
// kernel (a server's or a client's); nullopt while either topic has none.
// Throws TopicWithoutSchema and SchemaError as resolve_schema_topic() does,
// and ModuleNotLoaded.
std::optional<ServiceTypes> find_service_types(std::string_view service);

// Throws TypeMismatch, naming the service and both types, unless `types` are
// the parts of the service type `type` ("pkg/srv/Name" or "pkg/Name").
void require_service_type(const ServiceTypes& types, std::string_view service,
                          std::string_view type);

// What a topic carrying messages of compiled type T registers.
template <Publishable T>
SchemaTopic schema_topic_of(std::string topic) {
  SchemaTopic part;
  part.topic = std::move(topic);
  part.type_name = std::string(message_traits<T>::type_name);
  part.type_hash = message_traits<T>::type_hash;
  const auto blob = schema_of<T>();
  part.blob.assign(blob.begin(), blob.end());
  part.schema = parse_schema(part.blob);
  return part;
}

// The types of a service of compiled type Srv (a tool's own, or a test's).
template <class Srv>
ServiceTypes service_types_of(std::string_view service) {
  return {schema_topic_of<typename Srv::Request>(service_request_topic(service)),
          schema_topic_of<typename Srv::Response>(service_reply_topic(service))};
}

}  // namespace agnocast
