// Values written in .msg files (defaults and constants) turned into C++ expressions.
#pragma once

#include <string>
#include <string_view>

#include "message_spec.hpp"

namespace msggen {

// The C++ expression for `text` as a value of `type` (arrays as `[a, b]`).
// Throws std::invalid_argument saying why the value does not fit the type.
std::string cpp_value(const FieldType& type, std::string_view text);

// A C++ string literal holding exactly `text`.
std::string cpp_string_literal(std::string_view text);

// `text` without the white space at either end.
std::string_view trim(std::string_view text);

}  // namespace msggen
