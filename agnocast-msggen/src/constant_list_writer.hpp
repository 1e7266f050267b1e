// The names of a package's message constants as a C++ X-macro list, for
// agnocast_python_messages: its layout program takes every value from the
// generated C++ type itself, so a Python constant equals the C++ one.
#pragma once

#include <string>
#include <vector>

#include "message_spec.hpp"

namespace msggen {

// One line `AGNOCAST_CONSTANT(<Message>, <NAME>)` per constant of `messages`,
// in file order.
std::string write_constant_list(const std::vector<MessageSpec>& messages);

}  // namespace msggen
