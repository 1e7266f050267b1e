#include "agnocast/schema_layout.hpp"

#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "agnocast/allocator.hpp"

namespace agnocast {
namespace {

// Same layout as agnocast::allocator (stateless), but on the heap: for probing.
template <class T>
struct HeapAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = HeapAllocator<U>;
  };
  HeapAllocator() = default;
  template <class U>
  HeapAllocator(const HeapAllocator<U>&) noexcept {}
};
using ProbeVector = std::vector<std::uint64_t, HeapAllocator<std::uint64_t>>;
using ProbeString = std::basic_string<char, std::char_traits<char>, HeapAllocator<char>>;
static_assert(sizeof(ProbeVector) == sizeof(agnocast::vector<std::uint64_t>));
static_assert(sizeof(ProbeString) == sizeof(agnocast::string));

// Where in `object` a word equal to `value` is, other than at `skip`.
template <class Object>
std::uint8_t offset_of_word(const Object& object, std::uintptr_t value,
                            std::size_t skip = sizeof(Object)) {
  for (std::size_t offset = 0; offset + sizeof(value) <= sizeof(Object); offset += sizeof(value)) {
    if (offset == skip) continue;
    std::uintptr_t word;
    std::memcpy(&word, reinterpret_cast<const char*>(&object) + offset, sizeof(word));
    if (word == value) return static_cast<std::uint8_t>(offset);
  }
  throw std::logic_error("agnocast: unknown container layout in this standard library");
}

// Not inlined: GCC 12 at -O3 misreads the string's heap buffer as the constant 40
// (-Wfree-nonheap-object) once this is inlined into its caller.
[[gnu::noinline]] NativeContainerWords probe_container_words() {
  NativeContainerWords words;
  ContainerLayout& layout = words.layout;
  ProbeVector vector;
  vector.reserve(8);
  vector.resize(3);
  layout.pointer_size = sizeof(void*);
  layout.vector_size = sizeof(ProbeVector);
  layout.vector_begin_offset =
      offset_of_word(vector, reinterpret_cast<std::uintptr_t>(vector.data()));
  layout.vector_end_offset =
      offset_of_word(vector, reinterpret_cast<std::uintptr_t>(vector.data() + vector.size()));
  words.vector_capacity_offset =
      offset_of_word(vector, reinterpret_cast<std::uintptr_t>(vector.data() + vector.capacity()));

  ProbeString heap_string(40, 'x');  // longer than any small-string buffer
  heap_string.reserve(100);
  layout.string_size = sizeof(ProbeString);
  layout.string_data_offset =
      offset_of_word(heap_string, reinterpret_cast<std::uintptr_t>(heap_string.data()));
  layout.string_length_offset = offset_of_word(heap_string, heap_string.size());
  words.string_capacity_offset =
      offset_of_word(heap_string, heap_string.capacity(), layout.string_length_offset);

  const ProbeString local_string;
  const auto* object = reinterpret_cast<const char*>(&local_string);
  if (local_string.data() >= object && local_string.data() < object + sizeof(ProbeString)) {
    words.string_local_offset = static_cast<std::uint8_t>(local_string.data() - object);
    words.string_local_capacity = static_cast<std::uint8_t>(local_string.capacity());
  }
  return words;
}

}  // namespace

const NativeContainerWords& native_container_words() {
  static const NativeContainerWords words = probe_container_words();
  return words;
}

const ContainerLayout& native_container_layout() { return native_container_words().layout; }

}  // namespace agnocast
