// Every type of the standard set in messages/, compiled in: its name, hash
// and schema as a subscriber built with the generated headers registers
// them, for tools that publish a type they only know by name
// (agnocast-cli bag play of a file another tool wrote).
#pragma once

#include <agnocast/detail/endpoints.hpp>
#include <string_view>

namespace agnocast {

// The type "pkg/msg/Name", or nullptr for a type not in the set.
const detail::MessageType* standard_message_type(std::string_view type_name);

}  // namespace agnocast
