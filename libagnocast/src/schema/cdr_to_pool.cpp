#include "schema/cdr_to_pool.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "agnocast/cdr.hpp"

namespace agnocast::detail {
namespace {

// Reads XCDR1 (after the encapsulation header) into a message laid out as
// the schema says, containers as this process's standard library lays them
// out (the schema's own layout, checked by the caller). A first pass
// (memory == nullptr) only measures what the block needs after the message.
class CdrToPool {
 public:
  CdrToPool(const Schema& schema, std::span<const std::uint8_t> payload)
      : schema_(schema), in_(payload) {}

  std::size_t measure() {
    dry_ = true;
    position_ = 0;
    tail_ = schema_.types[0].size;
    message(schema_.types[0], nullptr);
    return tail_;
  }

  void fill(std::byte* block) {
    dry_ = false;
    position_ = 0;
    block_ = block;
    tail_ = schema_.types[0].size;
    std::memset(block, 0, schema_.types[0].size);
    message(schema_.types[0], block);
  }

 private:
  [[noreturn]] static void fail(const std::string& what) { throw cdr::Error("cdr: " + what); }
  void align(std::size_t size) {
    const std::size_t pad = (size - position_ % size) % size;
    take(pad);
  }
  const std::uint8_t* take(std::size_t bytes) {
    if (bytes > in_.size() - position_) fail("input ends inside the message");
    const std::uint8_t* at = in_.data() + position_;
    position_ += bytes;
    return at;
  }
  std::uint32_t count() {
    align(4);
    std::uint32_t value;
    std::memcpy(&value, take(4), 4);
    return value;
  }
  std::byte* reserve(std::size_t bytes, std::size_t align_to) {
    align_to = std::max<std::size_t>(align_to, 1);
    tail_ = (tail_ + align_to - 1) / align_to * align_to;
    std::byte* at = dry_ ? nullptr : block_ + tail_;
    tail_ += bytes;
    return at;
  }
  static void store_pointer(std::byte* at, const void* pointer) {
    std::memcpy(at, &pointer, sizeof pointer);
  }

  void message(const SchemaType& type, std::byte* at) {
    for (const SchemaField& field : type.fields) {
      std::byte* value = at ? at + field.offset : nullptr;
      switch (field.shape) {
        case FieldShape::Single:
          elements(field, value, 1);
          break;
        case FieldShape::Array:
          elements(field, value, field.array_length);
          break;
        case FieldShape::Sequence: {
          const std::uint32_t n = count();
          if (field.sequence_bound != 0 && n > field.sequence_bound) {
            fail("sequence '" + field.name + "' longer than its bound");
          }
          // Every element takes at least a byte: a longer count is a lie, not an allocation.
          if (n > in_.size() - position_)
            fail("sequence '" + field.name + "' longer than the input");
          const std::size_t bytes = static_cast<std::size_t>(n) * field.element_size;
          std::byte* first = reserve(bytes, field.element_align);
          // The measuring pass has no block: no address to compute, even unused.
          if (!dry_) {
            std::memset(first, 0, bytes);
            const NativeContainerWords& words = native_container_words();
            store_pointer(value + words.layout.vector_begin_offset, first);
            store_pointer(value + words.layout.vector_end_offset, first + bytes);
            store_pointer(value + words.vector_capacity_offset, first + bytes);
          }
          elements(field, first, n);
          break;
        }
      }
    }
  }

  void primitives(std::byte* at, std::size_t size, std::size_t n) {
    if (n == 0) return;
    align(size);
    const std::uint8_t* bytes = take(size * n);
    if (!dry_) std::memcpy(at, bytes, size * n);
  }

  void elements(const SchemaField& field, std::byte* at, std::size_t n) {
    switch (field.kind) {
      case FieldKind::Bool:
      case FieldKind::Int8:
      case FieldKind::UInt8:
        return primitives(at, 1, n);
      case FieldKind::Int16:
      case FieldKind::UInt16:
        return primitives(at, 2, n);
      case FieldKind::Int32:
      case FieldKind::UInt32:
      case FieldKind::Float32:
        return primitives(at, 4, n);
      case FieldKind::Int64:
      case FieldKind::UInt64:
      case FieldKind::Float64:
        return primitives(at, 8, n);
      case FieldKind::String:
        for (std::size_t i = 0; i < n; ++i)
          string(field, at ? at + i * field.element_size : nullptr);
        return;
      case FieldKind::Message:
        for (std::size_t i = 0; i < n; ++i) {
          message(schema_.types[field.nested], at ? at + i * field.element_size : nullptr);
        }
        return;
      case FieldKind::Opaque:
        break;
    }
    fail("field '" + field.name + "' holds opaque bytes, which have no CDR form");
  }

  void string(const SchemaField& field, std::byte* at) {
    const std::uint32_t length = count();
    if (length == 0) fail("string '" + field.name + "' of length 0 (it counts the NUL)");
    const auto* chars = take(length);
    if (chars[length - 1] != 0) fail("string '" + field.name + "' not terminated by NUL");
    const std::size_t size = length - 1;
    if (field.string_bound != 0 && size > field.string_bound) {
      fail("string '" + field.name + "' longer than its bound");
    }
    // A short string lives in its own local buffer, where the library expects
    // it; a longer one in the block, its capacity equal to its length.
    const NativeContainerWords& words = native_container_words();
    const bool local = words.string_local_capacity > 0 && size <= words.string_local_capacity;
    std::byte* data =
        local ? (at ? at + words.string_local_offset : nullptr) : reserve(size + 1, 1);
    if (dry_) return;
    std::memcpy(data, chars, size);
    data[size] = std::byte{0};
    store_pointer(at + words.layout.string_data_offset, data);
    std::memcpy(at + words.layout.string_length_offset, &size, sizeof size);
    if (!local) std::memcpy(at + words.string_capacity_offset, &size, sizeof size);
  }

  const Schema& schema_;
  std::span<const std::uint8_t> in_;
  std::size_t position_ = 0;
  std::size_t tail_ = 0;
  std::byte* block_ = nullptr;
  bool dry_ = true;
};

// XCDR1 little-endian: {0x00, 0x01} then two option bytes.
std::span<const std::uint8_t> payload_of(std::span<const std::uint8_t> cdr) {
  if (cdr.size() < 4 || cdr[0] != 0 || cdr[1] != 1) {
    throw cdr::Error("cdr: not little-endian XCDR1 (encapsulation header 00 01 missing)");
  }
  return cdr.subspan(4);
}

}  // namespace

std::size_t cdr_block_size(const Schema& schema, std::span<const std::uint8_t> cdr) {
  return CdrToPool(schema, payload_of(cdr)).measure();
}

void cdr_to_block(const Schema& schema, std::span<const std::uint8_t> cdr, std::byte* block) {
  CdrToPool(schema, payload_of(cdr)).fill(block);
}

std::size_t cdr_block_align(const Schema& schema) {
  return std::max<std::size_t>(schema.types.at(0).align, 8);
}

}  // namespace agnocast::detail
