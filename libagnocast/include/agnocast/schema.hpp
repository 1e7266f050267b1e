// The schema of a message type as a compact, versioned, bounded byte blob:
// what a publisher hands to the kernel (stored opaquely per topic) and what a
// reader that does not know the type at compile time (agnocast-cli topic echo)
// walks to decode a message in place.
//
// Format, version 2. All integers little-endian, records packed (no padding).
//   header, 20 bytes:
//     u32 magic "AGSC" (0x43534741)   u16 version (1)   u16 type_count (>= 1)
//     u32 total_bytes (the blob's length)
//     u8 pointer_size, u8 vector_size, u8 vector_begin_offset, u8 vector_end_offset,
//     u8 string_size, u8 string_data_offset, u8 string_length_offset, u8 zero
//       (where agnocast::vector keeps its begin and end pointers and agnocast::string
//        its data pointer and length, in the standard library that built the writer)
//   type_count type records, the message type first, each followed by its fields:
//     u64 hash, u32 size, u32 align, u16 field_count, u8 name_length, name bytes
//     field: u8 name_length, name bytes, u8 kind (FieldKind), u8 shape (FieldShape),
//            u16 nested (type index, 0xFFFF when kind is not Message),
//            u32 offset, size, element_size, element_align, array_length,
//                sequence_bound, string_bound
//   A nested type's index is always greater than its user's, so a reader never loops.
//   then for each type, in the same order: u32 definition_length, that many bytes of
//     its .msg text as agnocast-msggen read it (constants and comments included;
//     0 when it has none: a type declared in C++, or texts too large to fit)
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/limits.hpp"
#include "agnocast/message_traits.hpp"
#include "agnocast/schema_layout.hpp"

namespace agnocast {

inline constexpr std::uint32_t schema_magic = 0x43534741;  // "AGSC" in memory
inline constexpr std::uint16_t schema_format_version = 2;
inline constexpr std::uint16_t schema_no_type = 0xFFFF;

// A blob that is not a valid schema (what() says what is wrong), or a type too
// large to describe within schema_max_bytes.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SchemaField {
  std::string name;
  FieldKind kind = FieldKind::Opaque;
  FieldShape shape = FieldShape::Single;
  std::uint16_t nested = schema_no_type;
  std::uint32_t offset = 0;
  std::uint32_t size = 0;
  std::uint32_t element_size = 0;
  std::uint32_t element_align = 0;
  std::uint32_t array_length = 0;
  std::uint32_t sequence_bound = 0;
  std::uint32_t string_bound = 0;
};

struct SchemaType {
  std::string name;
  std::uint64_t hash = 0;
  std::uint32_t size = 0;
  std::uint32_t align = 0;
  std::vector<SchemaField> fields;
  // Its .msg text, constants and comments included; empty when it has none.
  std::string definition;
};

// A parsed, validated schema: types[0] is the message type.
struct Schema {
  ContainerLayout containers;
  std::vector<SchemaType> types;
};

// Throws SchemaError when `layout`, the one `type_name` was built with, is not
// this process's: its containers cannot then be built or changed in place
// here (`purpose` says what was attempted).
void require_native_layout(const ContainerLayout& layout, std::string_view type_name,
                           std::string_view purpose);

// Bytes of one number or bool of this kind; 0 for strings, messages and opaque bytes.
std::uint32_t primitive_size(FieldKind kind);
// The .msg name of a primitive kind ("int32", "string"); nullptr for messages
// and opaque bytes.
const char* primitive_name(FieldKind kind);

// The blob for a type and everything nested in it, with each type's .msg
// text; without the texts when they would not fit. Throws SchemaError when
// even that would exceed schema_max_bytes.
std::vector<std::uint8_t> build_schema(const TypeDescriptor& type);

// Checks every bound, index, size and offset (a reader can trust the result
// as far as the message's own bytes go). Throws SchemaError saying what is wrong.
Schema parse_schema(std::span<const std::uint8_t> blob);

// T's blob, built once.
template <Publishable T>
std::span<const std::uint8_t> schema_of() {
  static const std::vector<std::uint8_t> blob = build_schema(message_traits<T>::descriptor);
  return blob;
}

}  // namespace agnocast
