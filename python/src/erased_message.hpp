// Messages whose type is known only at run time, from its schema blob: what
// the Python binding needs to build, fill, read and destroy a message of a
// type agnocast-msggen generated C++ for, in place in the pool, without a
// compiled binding per type. Every offset and size comes from the schema the
// C++ compiler produced (agnocast::build_schema of the generated type), so the
// bytes are the ones a C++ endpoint of the same type reads and writes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "agnocast/errors.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/schema_walk.hpp"

namespace agnocast::python {

// A parsed schema with a name index per type; shared by every message of the type.
class ErasedSchema {
 public:
  // Throws SchemaError for an invalid blob, or one written by a standard
  // library whose containers differ from this one's.
  explicit ErasedSchema(std::vector<std::uint8_t> blob);

  const Schema& schema() const { return schema_; }
  std::span<const std::uint8_t> blob() const { return blob_; }
  const SchemaType& type(std::uint16_t index) const { return schema_.types.at(index); }
  // The field of type `index` called name, or nullptr.
  const SchemaField* field(std::uint16_t index, std::string_view name) const;

 private:
  std::vector<std::uint8_t> blob_;
  Schema schema_;
  std::vector<std::unordered_map<std::string, std::size_t>> names_;
};

// A received message whose containers point where they must not (outside the
// publisher's pool, misaligned, longer than their bound): raised naming the
// field, instead of reading there.
class InvalidMessage : public Error {
 public:
  using Error::Error;
};

// The bytes of an agnocast::vector<T> whose element size the schema gives.
struct VectorSpan {
  std::byte* data;
  std::size_t count;
};

// Operations on a message of type `index` at `message`. Writes need memory the
// caller owns; reads take the memory they may touch (trusted by default: a
// message this process built) and throw InvalidMessage where the message
// points outside it.
class ErasedOps {
 public:
  explicit ErasedOps(const ErasedSchema& schema) : schema_(schema) {}

  // Default-constructs the message in raw memory (numbers zero, containers empty).
  void construct(void* message, std::uint16_t index) const;
  // Destroys it: frees every vector's and string's pool memory.
  void destroy(void* message, std::uint16_t index) const noexcept;
  // Deep copy of one message of the type onto another (both constructed);
  // `from` may be a received message within from_memory.
  void copy(void* to, const void* from, std::uint16_t index,
            const ForeignMemory& from_memory = {}) const;

  // A Sequence field's elements, in place.
  VectorSpan sequence(const void* field_address, const SchemaField& field,
                      const ForeignMemory& memory = {}) const;
  // Resizes a Sequence field: new elements are default-constructed (zero).
  void resize_sequence(void* field_address, const SchemaField& field, std::size_t count) const;

  // A String element (a field, an array element or a sequence element).
  std::string_view string_at(const void* address, const SchemaField& field,
                             const ForeignMemory& memory = {}) const;
  void assign_string(void* address, std::string_view text) const;

 private:
  void construct_elements(std::byte* at, const SchemaField& field, std::size_t count) const;
  void destroy_elements(std::byte* at, const SchemaField& field, std::size_t count) const noexcept;
  void copy_field(std::byte* to, const std::byte* from, const SchemaField& field,
                  const ForeignMemory& from_memory) const;

  const ErasedSchema& schema_;
};

// Whether a kind is a number or bool (agnocast::primitive_size() gives its bytes).
bool is_primitive(FieldKind kind);

}  // namespace agnocast::python
