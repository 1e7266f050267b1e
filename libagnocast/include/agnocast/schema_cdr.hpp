// From a message's schema alone (no compiled type): its XCDR1 bytes, the same
// ones a generated type's cdr::serialize() writes and agnocast-bridge sends.
// agnocast-cli bag record writes them straight from the publisher's pool.
#pragma once

#include <cstddef>
#include <cstdint>
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

}  // namespace agnocast
