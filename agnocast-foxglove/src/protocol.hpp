// foxglove.websocket.v1 as agnocast-foxglove speaks it: the JSON ops and
// binary frames it sends, and the client requests it reads. Pure functions of
// their arguments, so the unit tests check every byte.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace agnocast::foxglove {

inline constexpr char subprotocol[] = "foxglove.websocket.v1";

struct Channel {
  std::uint32_t id = 0;
  std::string topic;
  std::string schema_name;  // "pkg/msg/Name"
  std::string schema;       // the full .msg text (ros2msg)
};

enum class StatusLevel { Info = 0, Warning = 1, Error = 2 };

std::string server_info_json(const std::string& name, const std::string& session_id);
std::string advertise_json(const std::vector<Channel>& channels);
std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids);
std::string status_json(StatusLevel level, const std::string& message);

// Binary: opcode 1, u32 subscription id, u64 timestamp (ns), the payload; little-endian.
std::string message_data_frame(std::uint32_t subscription_id, std::uint64_t timestamp_ns,
                               std::span<const std::uint8_t> payload);
// Binary: opcode 2, u64 timestamp (ns).
std::string time_frame(std::uint64_t timestamp_ns);

// A request the server cannot follow; what() is sent back as an error status.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Subscribe {
  struct Item {
    std::uint32_t id = 0;
    std::uint32_t channel_id = 0;
  };
  std::vector<Item> subscriptions;
};
struct Unsubscribe {
  std::vector<std::uint32_t> subscription_ids;
};
struct ClientAdvertise {
  struct Item {
    std::uint32_t id = 0;
    std::string topic;
    std::string encoding;
    std::string schema_name;
  };
  std::vector<Item> channels;
};
struct ClientUnadvertise {
  std::vector<std::uint32_t> channel_ids;
};
using ClientRequest = std::variant<Subscribe, Unsubscribe, ClientAdvertise, ClientUnadvertise>;

// A text frame. Throws ProtocolError for anything but one of the four ops above, well formed.
ClientRequest parse_client_request(const std::string& text);

struct ClientMessage {
  std::uint32_t channel_id = 0;
  std::span<const std::uint8_t> payload;  // into the frame
};
// A binary frame: opcode 1, u32 channel id, the payload. Throws ProtocolError.
ClientMessage parse_client_message(const std::string& frame);

}  // namespace agnocast::foxglove
