// A service type for the tests of SchemaClient and SchemaService, declared
// as agnocast-msggen would generate it, and its parts as ServiceTypes.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/allocator.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/schema_service_types.hpp"
#include "agnocast/service_traits.hpp"

namespace schema_service_test {

struct SumRequest {
  std::int64_t a = 0;
  std::int64_t b = 0;
};
struct SumResponse {
  std::int64_t sum = 0;
  agnocast::string note;
};
struct Sum {
  using Request = SumRequest;
  using Response = SumResponse;
};
// The same name with another response layout.
struct WideResponse {
  std::int64_t sum = 0;
  std::int64_t carry = 0;
};
struct Wide {
  using Request = SumRequest;
  using Response = WideResponse;
};

}  // namespace schema_service_test

AGNOCAST_MESSAGE(schema_service_test::SumRequest, "schema_service_test/srv/Sum_Request", a, b);
AGNOCAST_MESSAGE(schema_service_test::SumResponse, "schema_service_test/srv/Sum_Response", sum,
                 note);
AGNOCAST_MESSAGE(schema_service_test::WideResponse, "schema_service_test/srv/Sum_Response", sum,
                 carry);

template <>
struct agnocast::service_traits<schema_service_test::Sum> {
  static constexpr bool is_declared = true;
  static constexpr std::string_view type_name = "schema_service_test/srv/Sum";
  static constexpr std::uint64_t request_type_hash =
      message_traits<schema_service_test::SumRequest>::type_hash;
  static constexpr std::uint64_t response_type_hash =
      message_traits<schema_service_test::SumResponse>::type_hash;
};

template <>
struct agnocast::service_traits<schema_service_test::Wide> {
  static constexpr bool is_declared = true;
  static constexpr std::string_view type_name = "schema_service_test/srv/Sum";
  static constexpr std::uint64_t request_type_hash =
      message_traits<schema_service_test::SumRequest>::type_hash;
  static constexpr std::uint64_t response_type_hash =
      message_traits<schema_service_test::WideResponse>::type_hash;
};

namespace agnocast {

// What the kernel would report for a service of compiled type Srv.
template <class T>
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

template <class Srv>
ServiceTypes service_types_of(std::string_view service) {
  return {schema_topic_of<typename Srv::Request>(service_request_topic(service)),
          schema_topic_of<typename Srv::Response>(service_reply_topic(service))};
}

}  // namespace agnocast
