// What a Foxglove client sends agnocast-foxglove, as its WebSocket thread
// reads it: a text frame is one of the four ops the server follows or a
// ProtocolError, whose message (it quotes the client's bytes) still makes a
// status that is JSON; a binary frame is a client message whose payload is
// the rest of the frame, or a ProtocolError. The same bytes go to both.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "protocol.hpp"

namespace {

using namespace agnocast::foxglove;

// The server sends what() back as an error status: it must stay JSON.
void check_status_of(const ProtocolError& error) {
  const auto status =
      nlohmann::json::parse(status_json(StatusLevel::Error, error.what()), nullptr, false);
  if (status.is_discarded() || !status["message"].is_string()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string frame(reinterpret_cast<const char*>(data), size);
  try {
    parse_client_request(frame);
  } catch (const ProtocolError& error) {
    check_status_of(error);
  }
  try {
    const ClientMessage message = parse_client_message(frame);
    const auto* begin = reinterpret_cast<const std::uint8_t*>(frame.data());
    if (message.payload.data() != begin + 5 || message.payload.size() != frame.size() - 5) {
      std::abort();
    }
  } catch (const ProtocolError& error) {
    check_status_of(error);
  }
  return 0;
}
