// From a message's schema alone (no compiled type): its XCDR1 bytes, the same
// ones a generated type's cdr::serialize() writes and agnocast-bridge sends,
// and its ROS 2 .msg definition in the layout rosbag2 stores in MCAP files.
// agnocast-cli bag record uses both on messages straight from the
// publisher's pool.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/cdr.hpp"
#include "agnocast/schema.hpp"

namespace agnocast {

struct SchemaCdrOptions {
  // When set, the only bytes that may be read (the publisher's pool as this
  // process maps it): a pointer or length leading outside, a misaligned or
  // over-bound sequence is a cdr::Error, never a read outside.
  std::optional<std::span<const std::byte>> readable = std::nullopt;
  // The most bytes one message may produce: containers that alias one
  // another could otherwise multiply it without bound.
  std::size_t max_bytes = std::size_t{1} << 32;
};

// Appends the encapsulation header and the message to out (cleared first).
// Throws cdr::Error naming the field when the message cannot be written: a
// type without field descriptions (raw or opaque), or a check that fails.
void serialize_with_schema(const void* message, const Schema& schema,
                           std::vector<std::uint8_t>& out, const SchemaCdrOptions& options = {});

// "pkg/msg/Name" as .msg files name it: "pkg/Name".
std::string ros2msg_type_name(std::string_view type_name);

// The type's fields as .msg text, then for each type it uses (depth first,
// once each) a line of 80 '=', "MSG: pkg/Name" and that type's fields.
// Constants and comments are not in the schema, so not in the text.
// Throws cdr::Error for a type without field descriptions.
std::string ros2msg_definition(const Schema& schema);

// The same, with each type's own .msg text (constants and comments included,
// as rosbag2 writes it) where text_of("pkg/msg/Name") gives one (nullptr:
// none). A text is used only when its fields are the schema type's, by name
// and in order; else that type's fields are written from the schema.
using MsgTextLookup = std::function<const std::string_view*(std::string_view type_name)>;
std::string ros2msg_definition(const Schema& schema, const MsgTextLookup& text_of);

// The field names of a .msg text, in order (constants and comments skipped).
std::vector<std::string> msg_text_field_names(std::string_view text);

}  // namespace agnocast
