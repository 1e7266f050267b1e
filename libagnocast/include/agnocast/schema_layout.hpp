// Where agnocast::vector and agnocast::string keep their words in the standard
// library this library was built with, found once by probing real containers.
// A schema records the words a message's writer used (ContainerLayout); a
// reader or writer that touches containers without their C++ type (the
// renderer, the CDR writer and reader, Python) compares it with this
// process's (require_native_layout(), <agnocast/schema.hpp>) and asks here
// where the words it does not record lie.
#pragma once

#include <cstddef>
#include <cstdint>

namespace agnocast {

// What a schema records: enough to read a vector's elements and a string's
// characters.
struct ContainerLayout {
  std::uint8_t pointer_size = 0;
  std::uint8_t vector_size = 0;
  std::uint8_t vector_begin_offset = 0;
  std::uint8_t vector_end_offset = 0;
  std::uint8_t string_size = 0;
  std::uint8_t string_data_offset = 0;
  std::uint8_t string_length_offset = 0;

  bool operator==(const ContainerLayout&) const = default;
};

// What building a container in place also needs: the vector's end of storage
// and the string's small-string buffer (a string that fits it points there).
struct NativeContainerWords {
  ContainerLayout layout;
  std::uint8_t vector_capacity_offset = 0;
  // Byte offset of the string's local buffer and how many characters it holds
  // (0 and 0 when the library keeps every string on the heap).
  std::uint8_t string_local_offset = 0;
  std::uint8_t string_local_capacity = 0;
  // Where a heap string keeps its capacity.
  std::uint8_t string_capacity_offset = 0;
};

// The layout of this process's standard library.
const ContainerLayout& native_container_layout();
const NativeContainerWords& native_container_words();

}  // namespace agnocast
