// Reading a message in place from its schema alone, where the message may be
// another process's: every pointer and length it holds is input. The checks
// on that memory are written here once, and every reader of messages it did
// not build (topic echo's renderer, the CDR writer of bag record and the
// bridge, the Python binding's accessors) reads through them:
//   - the message, each sequence's elements and each string's characters lie
//     inside the publisher's pool as this process maps it;
//   - a sequence's begin and element type agree (aligned, end not before
//     begin, a whole number of elements, within its bound);
//   - nesting is no deeper than message_max_nesting (parse_schema refuses
//     deeper schemas, so walk_message never recurses further).
// A problem is a short static text ("sequence outside the publisher's pool")
// that a reader renders as a marker or throws, naming the field.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

#include "agnocast/schema.hpp"

namespace agnocast {

// The bytes a reader may touch.
class ForeignMemory {
 public:
  // A message this process built: every address it holds is trusted.
  ForeignMemory() = default;
  // Only `readable` may be read (the publisher's pool, mapped here).
  explicit ForeignMemory(std::span<const std::byte> readable)
      : begin_(reinterpret_cast<std::uintptr_t>(readable.data())),
        end_(begin_ + readable.size()),
        checked_(true) {}

  bool checked() const { return checked_; }
  // Whether `bytes` bytes from `at` lie inside (always, unchecked).
  bool contains(std::uintptr_t at, std::size_t bytes) const {
    return !checked_ || (at >= begin_ && at <= end_ && bytes <= end_ - at);
  }
  // Alignments a schema gives that are no power of two are not checked.
  static bool aligned(std::uintptr_t at, std::uint32_t align) {
    const bool power_of_two = align != 0 && (align & (align - 1)) == 0;
    return !power_of_two || at % align == 0;
  }

 private:
  std::uintptr_t begin_ = 0;
  std::uintptr_t end_ = 0;
  bool checked_ = false;
};

// The elements of an array or sequence field, or why they cannot be read.
struct ForeignElements {
  const std::byte* first = nullptr;
  std::size_t count = 0;
  const char* problem = nullptr;
};

// A string's characters, or why they cannot be read.
struct ForeignText {
  std::string_view text;
  const char* problem = nullptr;
};

// Why the message itself cannot be read (outside the memory, misaligned), or nullptr.
const char* message_problem(const SchemaType& type, const void* message,
                            const ForeignMemory& memory);

// The elements of an Array field (in place) or a Sequence field (its words
// read once: a publisher may rewrite them meanwhile, and checked). `field_at`
// is the field's own address.
ForeignElements field_elements(const ContainerLayout& layout, const SchemaField& field,
                               const std::byte* field_at, const ForeignMemory& memory);

// The characters of the string at `string_at` (a String field or element).
ForeignText string_text(const ContainerLayout& layout, const SchemaField& field,
                        const std::byte* string_at, const ForeignMemory& memory);

template <class T>
T load_unaligned(const std::byte* at) {
  T value;
  std::memcpy(&value, at, sizeof(T));
  return value;
}

// One walk over a message, shape by kind, with the checks above applied to
// every container; the visitor decides what each value becomes.
//   void begin_message(const SchemaType&)      / void end_message(const SchemaType&)
//   void begin_field(const SchemaField&)        / void end_field(const SchemaField&)
//   void scalar(const SchemaField&, const std::byte* at)        a number or bool
//   void numbers(const SchemaField&, const std::byte* first, std::size_t count)
//                                                array or sequence of numbers, in place
//   void text(const SchemaField&, ForeignText)   a string (its problem, if any, set)
//   bool begin_elements(const SchemaField&, ForeignElements)
//                                                an array or sequence: false skips its
//                                                elements (also when problem is set)
//   void begin_element(const SchemaField&, std::size_t index)
//   void end_elements(const SchemaField&)
//   void opaque(const SchemaField&, const std::byte* at, std::size_t count)
// Numbers of a Single field arrive through scalar(); of arrays and sequences
// through numbers(). Strings and nested messages of arrays and sequences come
// one element at a time between begin_element() calls.
template <class Visitor>
class SchemaWalk {
 public:
  SchemaWalk(const Schema& schema, const ForeignMemory& memory, Visitor& visitor)
      : schema_(schema), memory_(memory), visitor_(visitor) {}

  void message(const SchemaType& type, const std::byte* at) {
    visitor_.begin_message(type);
    for (const SchemaField& field : type.fields) {
      visitor_.begin_field(field);
      const std::byte* value = at + field.offset;
      if (field.shape == FieldShape::Single) {
        element(field, value);
      } else {
        elements(field, field_elements(schema_.containers, field, value, memory_));
      }
      visitor_.end_field(field);
    }
    visitor_.end_message(type);
  }

 private:
  static bool number(FieldKind kind) {
    return kind != FieldKind::String && kind != FieldKind::Message && kind != FieldKind::Opaque;
  }

  void element(const SchemaField& field, const std::byte* at) {
    switch (field.kind) {
      case FieldKind::String:
        visitor_.text(field, string_text(schema_.containers, field, at, memory_));
        return;
      case FieldKind::Message:
        message(schema_.types[field.nested], at);
        return;
      case FieldKind::Opaque:
        visitor_.opaque(field, at, 1);
        return;
      default:
        visitor_.scalar(field, at);
        return;
    }
  }

  void elements(const SchemaField& field, const ForeignElements& found) {
    if (!visitor_.begin_elements(field, found) || found.problem) return;
    if (number(field.kind)) {
      visitor_.numbers(field, found.first, found.count);
    } else if (field.kind == FieldKind::Opaque) {
      visitor_.opaque(field, found.first, found.count);
    } else {
      for (std::size_t i = 0; i < found.count; ++i) {
        visitor_.begin_element(field, i);
        element(field, found.first + i * field.element_size);
      }
    }
    visitor_.end_elements(field);
  }

  const Schema& schema_;
  const ForeignMemory& memory_;
  Visitor& visitor_;
};

}  // namespace agnocast
