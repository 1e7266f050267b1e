#include "service_wire.hpp"

#include <cstring>
#include <iomanip>
#include <sstream>

namespace agnocast_bridge {
namespace {

constexpr std::size_t encapsulation_size = 4;

}  // namespace

std::vector<std::uint8_t> with_request_header(const DdsRequestHeader& header,
                                              std::vector<std::uint8_t> message) {
  std::uint8_t bytes[dds_request_header_size];
  std::memcpy(bytes, &header.client, sizeof(header.client));
  std::memcpy(bytes + sizeof(header.client), &header.sequence, sizeof(header.sequence));
  // 16 bytes keep every later field's alignment, which counts from the end
  // of the encapsulation header.
  message.insert(message.begin() + encapsulation_size, std::begin(bytes), std::end(bytes));
  return message;
}

std::optional<SplitSample> split_request_header(std::span<const std::uint8_t> sample) {
  if (sample.size() < encapsulation_size + dds_request_header_size) return std::nullopt;
  SplitSample split;
  const std::uint8_t* header = sample.data() + encapsulation_size;
  std::memcpy(&split.header.client, header, sizeof(split.header.client));
  std::memcpy(&split.header.sequence, header + sizeof(split.header.client),
              sizeof(split.header.sequence));
  split.message.reserve(sample.size() - dds_request_header_size);
  split.message.assign(sample.begin(), sample.begin() + encapsulation_size);
  split.message.insert(split.message.end(),
                       sample.begin() + encapsulation_size + dds_request_header_size, sample.end());
  return split;
}

std::string service_user_data(const char* key, std::span<const std::uint8_t, 16> id) {
  std::ostringstream text;
  text << key << '=' << std::hex << std::setfill('0');
  for (std::size_t i = 0; i < id.size(); ++i) {
    text << (i == 0 ? "" : ".") << std::setw(2) << static_cast<int>(id[i]);
  }
  text << ';';
  return text.str();
}

}  // namespace agnocast_bridge
