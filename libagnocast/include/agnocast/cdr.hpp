// XCDR1 little-endian (CDR_LE): the bytes a ROS 2 / DDS peer expects.
// Generated messages provide cdr_write/cdr_read, found by argument-dependent
// lookup; serialize()/deserialize() add and check the 4-byte encapsulation header.
//
// Rules: primitives aligned to their size relative to the payload start (after
// the header); bool 1 byte; strings as uint32 length including the NUL, the
// bytes, the NUL; sequences as uint32 count, then the elements; fixed arrays as
// their elements only; nested messages inline.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace agnocast::cdr {

static_assert(std::endian::native == std::endian::little, "XCDR1 LE is written as-is");

// Input that is not valid XCDR1 for the type, or a value beyond a declared bound.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::array<std::uint8_t, 4> encapsulation_header{0x00, 0x01, 0x00, 0x00};

class Writer {
 public:
  explicit Writer(std::vector<std::uint8_t>& out) : out_(out), origin_(out.size()) {}

  template <class T>
  requires std::is_arithmetic_v<T>
  void write(T value) {
    align(sizeof(T));
    append(&value, sizeof(T));
  }

  template <class Traits, class Allocator>
  void write(const std::basic_string<char, Traits, Allocator>& text) {
    write(static_cast<std::uint32_t>(text.size() + 1));
    out_.insert(out_.end(), text.begin(), text.end());
    out_.push_back(0);
  }

  template <class E, std::size_t N>
  void write(const std::array<E, N>& elements) {
    write_elements(elements.data(), N);
  }

  template <class E, class Allocator>
  void write(const std::vector<E, Allocator>& elements) {
    write(static_cast<std::uint32_t>(elements.size()));
    write_elements(elements.data(), elements.size());
  }

  template <class Message>
  requires(!std::is_arithmetic_v<Message>) void write(const Message& message) {
    cdr_write(*this, message);
  }

  // count elements as a fixed array holds them (no count before them).
  template <class E>
  void write_elements(const E* elements, std::size_t count) {
    if constexpr (std::is_arithmetic_v<E>) {
      // Consecutive primitives of one size need no padding between them: one copy.
      if (count == 0) return;
      align(sizeof(E));
      append(elements, count * sizeof(E));
    } else {
      for (std::size_t i = 0; i < count; ++i) write(elements[i]);
    }
  }

 private:
  // Not inlined: GCC 12 at -O3, seeing a constant size grow a vector, warns
  // -Warray-bounds about the vector's own reallocation.
  [[gnu::noinline]] void append(const void* bytes, std::size_t size) {
    const std::size_t at = out_.size();
    out_.resize(at + size);
    std::memcpy(out_.data() + at, bytes, size);
  }

  void align(std::size_t size) {
    const std::size_t position = out_.size() - origin_;
    out_.resize(out_.size() + (size - position % size) % size, 0);
  }

  std::vector<std::uint8_t>& out_;
  std::size_t origin_;
};

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> payload) : in_(payload) {}

  template <class T>
  requires std::is_arithmetic_v<T>
  void read(T& value) {
    align(sizeof(T));
    if constexpr (std::is_same_v<T, bool>) {
      const std::uint8_t byte = *take(1);
      if (byte > 1) throw Error("cdr: bool is neither 0 nor 1");
      value = byte == 1;
    } else {
      std::memcpy(&value, take(sizeof(T)), sizeof(T));
    }
  }

  template <class Traits, class Allocator>
  void read(std::basic_string<char, Traits, Allocator>& text) {
    const std::uint32_t length = read_count();
    if (length == 0) throw Error("cdr: string length 0 (it counts the NUL)");
    const auto* bytes = reinterpret_cast<const char*>(take(length));
    if (bytes[length - 1] != '\0') throw Error("cdr: string not terminated by NUL");
    text.assign(bytes, length - 1);
  }

  template <class E, std::size_t N>
  void read(std::array<E, N>& elements) {
    read_elements(elements.data(), N);
  }

  template <class E, class Allocator>
  void read(std::vector<E, Allocator>& elements) {
    const std::uint32_t count = read_count();
    // Each element takes at least one byte: a count beyond the input is a lie, not an allocation.
    if (count > remaining()) throw Error("cdr: sequence longer than the input");
    elements.clear();
    elements.resize(count);
    read_elements(elements.data(), count);
  }

  template <class Message>
  requires(!std::is_arithmetic_v<Message>) void read(Message& message) { cdr_read(*this, message); }

  std::size_t remaining() const { return in_.size() - position_; }

 private:
  template <class E>
  void read_elements(E* elements, std::size_t count) {
    if constexpr (std::is_arithmetic_v<E> && !std::is_same_v<E, bool>) {
      if (count == 0) return;
      align(sizeof(E));
      if (count > remaining() / sizeof(E)) throw Error("cdr: input ends inside the message");
      std::memcpy(elements, take(count * sizeof(E)), count * sizeof(E));
    } else {
      for (std::size_t i = 0; i < count; ++i) read(elements[i]);  // bools are checked one by one
    }
  }

  std::uint32_t read_count() {
    std::uint32_t count = 0;
    read(count);
    return count;
  }
  void align(std::size_t size) { take((size - position_ % size) % size); }
  const std::uint8_t* take(std::size_t bytes) {
    if (bytes > remaining()) throw Error("cdr: input ends inside the message");
    const std::uint8_t* at = in_.data() + position_;
    position_ += bytes;
    return at;
  }

  std::span<const std::uint8_t> in_;
  std::size_t position_ = 0;
};

// Throws Error when a bounded string or sequence holds more than its bound.
inline void check_bound(std::size_t size, std::size_t bound, const char* field) {
  if (size > bound) {
    throw Error(std::string("cdr: ") + field + " holds " + std::to_string(size) +
                " elements, more than its bound " + std::to_string(bound));
  }
}

// The encapsulation header, then the message.
template <class Message>
std::vector<std::uint8_t> serialize(const Message& message) {
  std::vector<std::uint8_t> out(encapsulation_header.begin(), encapsulation_header.end());
  Writer writer(out);  // aligns relative to here, the payload start
  writer.write(message);
  return out;
}

// Reads a message written by serialize() (or any XCDR1 LE writer); bytes after
// the message are padding and ignored.
template <class Message>
void deserialize(std::span<const std::uint8_t> bytes, Message& message) {
  if (bytes.size() < encapsulation_header.size() || bytes[0] != 0x00 || bytes[1] != 0x01) {
    throw Error("cdr: no CDR_LE encapsulation header (00 01 00 00)");
  }
  Reader reader(bytes.subspan(encapsulation_header.size()));
  reader.read(message);
}

}  // namespace agnocast::cdr
