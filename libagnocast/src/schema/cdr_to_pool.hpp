// XCDR1 bytes back into the message they encode, from its schema alone, in
// one block: the message, then the elements of its sequences and the
// characters of its long strings, so that freeing the block frees everything
// and nothing needs a destructor. Containers are laid out as this process's
// standard library lays them out; the caller checks that the schema's layout
// is this process's (require_native_layout()). What SchemaPublisher publishes
// (bag play, agnocast-foxglove) and SchemaClient sends (service call).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "agnocast/detail/message.hpp"
#include "agnocast/schema.hpp"

namespace agnocast::detail {

// The bytes the block for `cdr` (little-endian XCDR1, encapsulation header
// included) takes, after checking every count, bound and string against the
// schema. Throws cdr::Error, naming the field, when they are not a message of it.
std::size_t cdr_block_size(const Schema& schema, std::span<const std::uint8_t> cdr);

// Writes the message into `block`: cdr_block_size() bytes, aligned at least
// as the message type. Throws as cdr_block_size() does.
void cdr_to_block(const Schema& schema, std::span<const std::uint8_t> cdr, std::byte* block);

// The alignment a block needs.
std::size_t cdr_block_align(const Schema& schema);

struct CdrLoan {
  void* message = nullptr;  // a loan of this process's pool, as allocate_message() gives
  std::size_t bytes = 0;    // the block's size, for the kernel's bandwidth counter
};

inline void leave_to_block(void*) {}  // the block holds everything: freeing it is all

// The message of `cdr` as a loan, ready to publish. Throws cdr::Error with
// nothing allocated when the bytes are not a message of the schema.
inline CdrLoan loan_from_cdr(const Schema& schema, std::span<const std::uint8_t> cdr) {
  const std::size_t size = cdr_block_size(schema, cdr);
  void* memory = allocate_message(size, cdr_block_align(schema), &leave_to_block);
  try {
    cdr_to_block(schema, cdr, static_cast<std::byte*>(memory));
  } catch (...) {
    free_message_memory(memory);
    throw;
  }
  return {memory, size};
}

}  // namespace agnocast::detail
