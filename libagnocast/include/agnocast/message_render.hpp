// Renders a message in place, from its schema alone: what `agnocast-cli topic
// echo` prints. Unchecked, the message and every container it holds must be
// readable at the addresses they point to (a trusted in-process message).
// Checked (RenderOptions::readable set), nothing outside that range is ever
// read: a message from another process cannot crash the reader, whatever its
// pointers and lengths hold.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include "agnocast/schema.hpp"

namespace agnocast {

struct RenderOptions {
  // false: arrays and sequences show their length only (echo --no-arrays).
  bool show_arrays = true;
  // When set, the only bytes the renderer may read (the publisher's pool as
  // this process maps it). The message, every sequence's elements and every
  // string's characters must lie inside; a sequence whose end precedes its
  // begin, whose length breaks its bound or is no whole number of elements,
  // or whose elements are misaligned renders as an invalid marker instead
  // (text `<invalid: REASON>`, JSON {"invalid":"REASON"}).
  std::optional<std::span<const std::byte>> readable = std::nullopt;
  // Checked only: how many elements and string bytes one message may show in
  // all; containers that alias one another could otherwise multiply the output
  // without bound. Past it, containers render as invalid markers.
  std::size_t max_values = std::size_t{1} << 24;
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
