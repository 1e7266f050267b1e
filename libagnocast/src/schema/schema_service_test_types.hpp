// A service type for the tests of services (Service and Client, SchemaClient
// and SchemaService), declared as agnocast-msggen would generate it.
#pragma once

#include <cstdint>
#include <string_view>

#include "agnocast/allocator.hpp"
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
