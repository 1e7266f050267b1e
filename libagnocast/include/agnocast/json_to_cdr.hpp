// A message written as JSON, turned into its XCDR1 bytes from its schema
// alone: what `agnocast-cli service call` sends. The JSON is what
// render_message_json() prints (<agnocast/message_render.hpp>): an object of
// the fields by name, nested messages as objects, arrays and sequences as
// arrays, numbers as numbers, bools as true/false, strings as strings. A
// field left out takes its zero value (0, false, "", no elements; a fixed
// array N zeros); the .msg file's default values are not known here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/schema.hpp"

namespace agnocast {

// The JSON is no message of the type; what() names the field (its path from
// the message, e.g. "cells[2].note") and the rule it breaks.
class JsonInputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct JsonToCdrOptions {
  // The most bytes the message may take: a fixed array of a large type left
  // out would otherwise be written in full, however short the JSON.
  std::size_t max_bytes = std::size_t{1} << 30;
};

// The encapsulation header and the message. Throws JsonInputError for text
// that is not JSON, nests deeper than any message can, or is not a message
// of the schema's type: a field the type has not, a value of another kind,
// an integer out of its type's range, a float beyond float32's, an array of
// another length than the type's, a sequence or string beyond its bound, a
// string holding a NUL. Also for a type CDR cannot write (opaque bytes).
std::vector<std::uint8_t> json_to_cdr(std::string_view json, const Schema& schema,
                                      const JsonToCdrOptions& options = {});

// Empty when `json` is JSON nested no deeper than a message can be, else
// what json_to_cdr() would throw for it: for checking the text before the
// type is known.
std::string json_syntax_problem(std::string_view json);

}  // namespace agnocast
