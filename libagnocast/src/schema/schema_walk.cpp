#include "agnocast/schema_walk.hpp"

namespace agnocast {
namespace {

// What a reader gets instead of the container.
struct Refusal {
  const char* problem;
  operator ForeignElements() const { return {nullptr, 0, problem}; }
  operator ForeignText() const { return {{}, problem}; }
};
Refusal refused(const char* problem) { return {problem}; }

}  // namespace

const char* message_problem(const SchemaType& type, const void* message,
                            const ForeignMemory& memory) {
  const auto at = reinterpret_cast<std::uintptr_t>(message);
  if (!memory.contains(at, type.size)) return "message outside the publisher's pool";
  if (memory.checked() && !ForeignMemory::aligned(at, type.align)) return "misaligned message";
  return nullptr;
}

ForeignElements field_elements(const ContainerLayout& layout, const SchemaField& field,
                               const std::byte* field_at, const ForeignMemory& memory) {
  if (field.shape == FieldShape::Array) return {field_at, field.array_length, nullptr};
  if (field.shape != FieldShape::Sequence) return {field_at, 1, nullptr};
  const auto begin = load_unaligned<std::uintptr_t>(field_at + layout.vector_begin_offset);
  const auto end = load_unaligned<std::uintptr_t>(field_at + layout.vector_end_offset);
  if (end < begin) return refused("sequence ends before its begin");
  const std::size_t bytes = end - begin;
  // parse_schema refuses element size 0; bytes / size cannot then overflow when
  // multiplied back, so no count here ever exceeds the memory it was read from.
  if (bytes % field.element_size != 0) {
    return refused("sequence length is no whole number of elements");
  }
  const std::size_t count = bytes / field.element_size;
  if (field.sequence_bound != 0 && count > field.sequence_bound) {
    return refused("sequence longer than its bound");
  }
  if (count == 0) return {};
  if (memory.checked() && !ForeignMemory::aligned(begin, field.element_align)) {
    return refused("misaligned sequence");
  }
  if (!memory.contains(begin, bytes)) return refused("sequence outside the publisher's pool");
  return {reinterpret_cast<const std::byte*>(begin), count, nullptr};
}

ForeignText string_text(const ContainerLayout& layout, const SchemaField& field,
                        const std::byte* string_at, const ForeignMemory& memory) {
  const auto data = load_unaligned<std::uintptr_t>(string_at + layout.string_data_offset);
  const auto length = load_unaligned<std::size_t>(string_at + layout.string_length_offset);
  if (field.string_bound != 0 && length > field.string_bound) {
    return refused("string longer than its bound");
  }
  if (length == 0) return {};
  if (!memory.contains(data, length)) return refused("string outside the publisher's pool");
  return {std::string_view(reinterpret_cast<const char*>(data), length), nullptr};
}

}  // namespace agnocast
