// The ROS 2 .msg grammar: one member per line, `type name [default]` for a
// field and `type NAME=value` for a constant, `#` comments.
#pragma once

#include <string>
#include <string_view>

#include "message_spec.hpp"

namespace msggen {

// Parses the text of `file`, message `package/name`. Types are not resolved
// here, but same-package references get `package` filled in. Throws InputError.
MessageSpec parse_message(std::string_view text, const std::string& file,
                          const std::string& package, const std::string& name);

}  // namespace msggen
