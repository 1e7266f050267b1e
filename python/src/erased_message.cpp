#include "erased_message.hpp"

#include <cstring>
#include <new>
#include <vector>

#include "agnocast/allocator.hpp"

namespace agnocast::python {
namespace {

std::byte* read_pointer(const void* vector, std::size_t offset) {
  std::byte* value;
  std::memcpy(&value, static_cast<const std::byte*>(vector) + offset, sizeof(value));
  return value;
}

void write_pointer(void* vector, std::size_t offset, std::byte* value) {
  std::memcpy(static_cast<std::byte*>(vector) + offset, &value, sizeof(value));
}

}  // namespace

bool is_primitive(FieldKind kind) { return primitive_size(kind) != 0; }

ErasedSchema::ErasedSchema(std::vector<std::uint8_t> blob)
    : blob_(std::move(blob)), schema_(parse_schema(blob_)) {
  require_native_layout(schema_.containers, schema_.types[0].name, "the Python binding");
  names_.resize(schema_.types.size());
  for (std::size_t t = 0; t < schema_.types.size(); ++t) {
    const auto& fields = schema_.types[t].fields;
    for (std::size_t f = 0; f < fields.size(); ++f) {
      if (fields[f].kind == FieldKind::Opaque) {
        throw SchemaError("agnocast: field '" + fields[f].name + "' of " + schema_.types[t].name +
                          " has no description; Python cannot read it");
      }
      names_[t].emplace(fields[f].name, f);
    }
  }
}

const SchemaField* ErasedSchema::field(std::uint16_t index, std::string_view name) const {
  const auto& names = names_.at(index);
  const auto found = names.find(std::string(name));
  if (found == names.end()) return nullptr;
  return &schema_.types[index].fields[found->second];
}

void ErasedOps::construct(void* message, std::uint16_t index) const {
  const SchemaType& type = schema_.type(index);
  auto* bytes = static_cast<std::byte*>(message);
  std::memset(bytes, 0, type.size);
  for (const SchemaField& field : type.fields) {
    std::byte* at = bytes + field.offset;
    switch (field.shape) {
      case FieldShape::Single:
        construct_elements(at, field, 1);
        break;
      case FieldShape::Array:
        construct_elements(at, field, field.array_length);
        break;
      case FieldShape::Sequence:
        // An empty vector: three null pointers (the memset), as the constructor leaves it.
        ::new (at) agnocast::vector<std::uint8_t>();
        break;
    }
  }
}

void ErasedOps::construct_elements(std::byte* at, const SchemaField& field,
                                   std::size_t count) const {
  if (field.kind == FieldKind::String) {
    for (std::size_t i = 0; i < count; ++i) ::new (at + i * field.element_size) agnocast::string();
  } else if (field.kind == FieldKind::Message) {
    for (std::size_t i = 0; i < count; ++i) construct(at + i * field.element_size, field.nested);
  } else {
    std::memset(at, 0, count * field.element_size);
  }
}

void ErasedOps::destroy_elements(std::byte* at, const SchemaField& field,
                                 std::size_t count) const noexcept {
  if (field.kind == FieldKind::String) {
    for (std::size_t i = 0; i < count; ++i) {
      std::launder(reinterpret_cast<agnocast::string*>(at + i * field.element_size))
          ->~basic_string();
    }
  } else if (field.kind == FieldKind::Message) {
    for (std::size_t i = 0; i < count; ++i) destroy(at + i * field.element_size, field.nested);
  }
}

void ErasedOps::destroy(void* message, std::uint16_t index) const noexcept {
  const SchemaType& type = schema_.type(index);
  auto* bytes = static_cast<std::byte*>(message);
  for (const SchemaField& field : type.fields) {
    std::byte* at = bytes + field.offset;
    switch (field.shape) {
      case FieldShape::Single:
        destroy_elements(at, field, 1);
        break;
      case FieldShape::Array:
        destroy_elements(at, field, field.array_length);
        break;
      case FieldShape::Sequence: {
        // This process's own vector, read as it is (no check may throw here).
        const NativeContainerWords& words = native_container_words();
        std::byte* begin = read_pointer(at, words.layout.vector_begin_offset);
        std::byte* end = read_pointer(at, words.layout.vector_end_offset);
        const std::size_t count =
            begin ? static_cast<std::size_t>(end - begin) / field.element_size : 0;
        destroy_elements(begin, field, count);
        if (begin) detail::pool_deallocate(begin);
        std::memset(at, 0, field.size);
        break;
      }
    }
  }
}

VectorSpan ErasedOps::sequence(const void* field_address, const SchemaField& field,
                               const ForeignMemory& memory) const {
  const ForeignElements found = field_elements(
      schema_.schema().containers, field, static_cast<const std::byte*>(field_address), memory);
  if (found.problem) {
    throw InvalidMessage("agnocast: field '" + field.name +
                         "' of a received message: " + found.problem);
  }
  // Writable only where the message is this process's loan (the caller's to know).
  return {const_cast<std::byte*>(found.first), found.count};
}

void ErasedOps::resize_sequence(void* field_address, const SchemaField& field,
                                std::size_t count) const {
  const NativeContainerWords& words = native_container_words();
  const std::size_t size = field.element_size;
  std::byte* begin = read_pointer(field_address, words.layout.vector_begin_offset);
  std::byte* end = read_pointer(field_address, words.layout.vector_end_offset);
  std::byte* capacity_end = read_pointer(field_address, words.vector_capacity_offset);
  const std::size_t current = begin ? static_cast<std::size_t>(end - begin) / size : 0;
  const std::size_t capacity = begin ? static_cast<std::size_t>(capacity_end - begin) / size : 0;
  if (count <= current) {
    destroy_elements(begin + count * size, field, current - count);
    if (begin) write_pointer(field_address, words.layout.vector_end_offset, begin + count * size);
    return;
  }
  if (count <= capacity) {
    construct_elements(end, field, count - current);
    write_pointer(field_address, words.layout.vector_end_offset, begin + count * size);
    return;
  }
  if (count > (std::size_t{1} << 40) / size) throw std::bad_array_new_length();
  auto* fresh = static_cast<std::byte*>(detail::pool_allocate(count * size, field.element_align));
  construct_elements(fresh, field, count);
  if (is_primitive(field.kind)) {
    if (current) std::memcpy(fresh, begin, current * size);
  } else {
    try {
      for (std::size_t i = 0; i < current; ++i) {
        if (field.kind == FieldKind::String) {
          assign_string(fresh + i * size, string_at(begin + i * size, field));
        } else {
          copy(fresh + i * size, begin + i * size, field.nested);
        }
      }
    } catch (...) {
      destroy_elements(fresh, field, count);
      detail::pool_deallocate(fresh);
      throw;
    }
  }
  destroy_elements(begin, field, current);
  if (begin) detail::pool_deallocate(begin);
  write_pointer(field_address, words.layout.vector_begin_offset, fresh);
  write_pointer(field_address, words.layout.vector_end_offset, fresh + count * size);
  write_pointer(field_address, words.vector_capacity_offset, fresh + count * size);
}

std::string_view ErasedOps::string_at(const void* address, const SchemaField& field,
                                      const ForeignMemory& memory) const {
  const ForeignText found = string_text(schema_.schema().containers, field,
                                        static_cast<const std::byte*>(address), memory);
  if (found.problem) {
    throw InvalidMessage("agnocast: field '" + field.name +
                         "' of a received message: " + found.problem);
  }
  return found.text;
}

void ErasedOps::assign_string(void* address, std::string_view text) const {
  std::launder(reinterpret_cast<agnocast::string*>(address))->assign(text.data(), text.size());
}

void ErasedOps::copy_field(std::byte* to, const std::byte* from, const SchemaField& field,
                           const ForeignMemory& from_memory) const {
  if (field.shape == FieldShape::Sequence) {
    const VectorSpan source = sequence(from, field, from_memory);
    resize_sequence(to, field, source.count);
    const VectorSpan target = sequence(to, field);
    if (is_primitive(field.kind)) {
      if (source.count) std::memcpy(target.data, source.data, source.count * field.element_size);
      return;
    }
    for (std::size_t i = 0; i < source.count; ++i) {
      const std::size_t at = i * field.element_size;
      if (field.kind == FieldKind::String) {
        assign_string(target.data + at, string_at(source.data + at, field, from_memory));
      } else {
        copy(target.data + at, source.data + at, field.nested, from_memory);
      }
    }
    return;
  }
  const std::size_t count = field.shape == FieldShape::Array ? field.array_length : 1;
  if (is_primitive(field.kind)) {
    std::memmove(to, from, count * field.element_size);
    return;
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t at = i * field.element_size;
    if (field.kind == FieldKind::String) {
      assign_string(to + at, string_at(from + at, field, from_memory));
    } else {
      copy(to + at, from + at, field.nested, from_memory);
    }
  }
}

void ErasedOps::copy(void* to, const void* from, std::uint16_t index,
                     const ForeignMemory& from_memory) const {
  if (to == from) return;
  for (const SchemaField& field : schema_.type(index).fields) {
    copy_field(static_cast<std::byte*>(to) + field.offset,
               static_cast<const std::byte*>(from) + field.offset, field, from_memory);
  }
}

}  // namespace agnocast::python
