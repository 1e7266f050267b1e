// The message of agnocast-talker and agnocast-listener. Payload bytes and the
// checksum are a pure function of seq, so the listener detects any corruption.
#pragma once

#include <agnocast/agnocast.hpp>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace chatter {

struct Message {
  std::uint64_t seq = 0;
  std::uint64_t checksum = 0;
  agnocast::vector<std::uint8_t> payload;
};

}  // namespace chatter

AGNOCAST_MESSAGE(chatter::Message, "chatter/msg/Message", seq, checksum, payload);

namespace chatter {

inline std::uint64_t mix(std::uint64_t value) {  // splitmix64's finalizer
  value += 0x9E3779B97F4A7C15ULL;
  value = (value ^ (value >> 30)) * 0xBF58476D1CE4E5B9ULL;
  value = (value ^ (value >> 27)) * 0x94D049BB133111EBULL;
  return value ^ (value >> 31);
}

inline std::uint64_t payload_word(std::uint64_t seq, std::size_t index) {
  return mix(seq * 0x100000001B3ULL + index);
}

inline std::uint64_t checksum_of(std::uint64_t seq, std::size_t size) {
  return mix(seq ^ 0xA6A0CA57ULL) ^ size;
}

inline void fill(Message& message, std::uint64_t seq, std::size_t size) {
  message.seq = seq;
  message.checksum = checksum_of(seq, size);
  message.payload.resize(size);
  std::uint8_t* bytes = message.payload.data();
  for (std::size_t offset = 0; offset < size; offset += 8) {
    const std::uint64_t word = payload_word(seq, offset / 8);
    std::memcpy(bytes + offset, &word, size - offset < 8 ? size - offset : 8);
  }
}

inline bool verify(const Message& message) {
  const std::size_t size = message.payload.size();
  if (message.checksum != checksum_of(message.seq, size)) return false;
  const std::uint8_t* bytes = message.payload.data();
  for (std::size_t offset = 0; offset < size; offset += 8) {
    const std::uint64_t word = payload_word(message.seq, offset / 8);
    if (std::memcmp(bytes + offset, &word, size - offset < 8 ? size - offset : 8) != 0) {
      return false;
    }
  }
  return true;
}

}  // namespace chatter
