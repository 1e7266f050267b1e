// What a service type is: agnocast-msggen makes pkg::srv::Name from a .srv
// file, with Name::Request and Name::Response, each an ordinary message
// (pkg::srv::Name_Request, pkg::srv::Name_Response), and specializes
// service_traits<Name> with the service's type name and both parts' hashes.
#pragma once

#include <concepts>
#include <cstdint>
#include <string_view>

#include "agnocast/message_traits.hpp"

namespace agnocast {

// Specialized by agnocast-msggen: is_declared = true, type_name
// ("pkg/srv/Name"), request_type_hash and response_type_hash.
template <class Srv>
struct service_traits {
  static constexpr bool is_declared = false;
};

namespace detail {
template <class Srv>
concept HasServiceTraits = requires {
  { service_traits<Srv>::type_name } -> std::convertible_to<std::string_view>;
  { service_traits<Srv>::request_type_hash } -> std::convertible_to<std::uint64_t>;
  { service_traits<Srv>::response_type_hash } -> std::convertible_to<std::uint64_t>;
};
}  // namespace detail

// A server and a client meet on a service of this type when both hashes match.
template <class Srv>
concept ServiceType = service_traits<Srv>::is_declared && detail::HasServiceTraits<Srv> &&
    DeclaredMessage<typename Srv::Request> && DeclaredMessage<typename Srv::Response>;

}  // namespace agnocast
