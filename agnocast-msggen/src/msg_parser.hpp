// The ROS 2 .msg grammar: one member per line, `type name [default]` for a
// field and `type NAME=value` for a constant, `#` comments; and .srv files,
// two such parts around a line `---`.
#pragma once

#include <string>
#include <string_view>

#include "message_spec.hpp"

namespace msggen {

// Parses the text of `file`, message `package/name`. Types are not resolved
// here, but same-package references get `package` filled in. Throws InputError.
MessageSpec parse_message(std::string_view text, const std::string& file,
                          const std::string& package, const std::string& name);

// Parses the text of `file`, service `package/name`: the lines before the line
// `---` are the request `name_Request`, those after it the response
// `name_Response`, each a message of kind "srv" whose text is its part of the
// file. Errors keep the file's line numbers. Throws InputError.
ServiceSpec parse_service(std::string_view text, const std::string& file,
                          const std::string& package, const std::string& name);

}  // namespace msggen
