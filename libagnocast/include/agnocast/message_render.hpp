// Renders a message in place, from its schema alone: what `agnocast-cli topic
// echo` prints. The message and every container it holds must be readable at
// the addresses they point to (a subscriber's read-only mapping of the pool).
#pragma once

#include <string>

#include "agnocast/schema.hpp"

namespace agnocast {

struct RenderOptions {
  // false: arrays and sequences show their length only (echo --no-arrays).
  bool show_arrays = true;
};

// YAML-like text, one field per line, nested messages indented by two spaces;
// ends with a newline.
std::string render_message_text(const void* message, const Schema& schema,
                                const RenderOptions& options = {});

// One JSON object on one line, no newline; fields in declaration order. Without
// arrays, each array or sequence becomes {"length": N}. Non-finite floats are null.
std::string render_message_json(const void* message, const Schema& schema,
                                const RenderOptions& options = {});

}  // namespace agnocast
