// Renders a message in place, from its schema alone: what `agnocast-cli topic
// echo` prints. The message and every container it holds must be readable at
// the addresses they point to (a subscriber's read-only mapping of the pool).
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "agnocast/schema.hpp"

namespace agnocast {

struct RenderOptions {
  // false: arrays and sequences show their length only (echo --no-arrays).
  bool show_arrays = true;
  // When set, the bytes of every string and sequence the message points to are
  // read only if this says they are mapped (e.g. inside a publisher's pool);
  // otherwise, and for a vector whose pointers make no sense, the value is shown
  // as <unreadable> (JSON null). Unset: every pointer is trusted.
  std::function<bool(const void* address, std::size_t bytes)> readable = nullptr;
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
