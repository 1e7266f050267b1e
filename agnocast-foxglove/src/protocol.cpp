#include "protocol.hpp"

#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

namespace agnocast::foxglove {
namespace {

using nlohmann::json;

void append_le(std::string& out, std::uint64_t value, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes; ++i)
    out.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

const json& member(const json& object, const char* name) {
  const auto found = object.find(name);
  if (found == object.end()) throw ProtocolError(std::string("missing field '") + name + "'");
  return *found;
}

std::uint32_t id_field(const json& object, const char* name) {
  const json& value = member(object, name);
  if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 0xFFFFFFFFu) {
    throw ProtocolError(std::string("field '") + name + "' is not an id (an integer 0..2^32-1)");
  }
  return value.get<std::uint32_t>();
}

std::string string_field(const json& object, const char* name) {
  const json& value = member(object, name);
  if (!value.is_string()) throw ProtocolError(std::string("field '") + name + "' is not a string");
  return value.get<std::string>();
}

const json& array_field(const json& object, const char* name) {
  const json& value = member(object, name);
  if (!value.is_array()) throw ProtocolError(std::string("field '") + name + "' is not an array");
  return value;
}

std::vector<std::uint32_t> id_array(const json& object, const char* name) {
  std::vector<std::uint32_t> ids;
  for (const json& value : array_field(object, name)) {
    if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 0xFFFFFFFFu) {
      throw ProtocolError(std::string("'") + name + "' holds something that is not an id");
    }
    ids.push_back(value.get<std::uint32_t>());
  }
  return ids;
}

const json& object_item(const json& item) {
  if (!item.is_object()) throw ProtocolError("an array item is not an object");
  return item;
}

}  // namespace

std::string server_info_json(const std::string& name, const std::string& session_id) {
  return json{{"op", "serverInfo"},
              {"name", name},
              {"capabilities", {"clientPublish", "time"}},
              {"supportedEncodings", {"cdr"}},
              {"metadata", json::object()},
              {"sessionId", session_id}}
      .dump();
}

std::string advertise_json(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const Channel& channel : channels) {
    list.push_back({{"id", channel.id},
                    {"topic", channel.topic},
                    {"encoding", "cdr"},
                    {"schemaName", channel.schema_name},
                    {"schema", channel.schema},
                    {"schemaEncoding", "ros2msg"}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids) {
  return json{{"op", "unadvertise"}, {"channelIds", channel_ids}}.dump();
}

std::string status_json(StatusLevel level, const std::string& message) {
  // Replacement characters: a client's bytes quoted back may not be UTF-8.
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::string message_data_frame(std::uint32_t subscription_id, std::uint64_t timestamp_ns,
                               std::span<const std::uint8_t> payload) {
  std::string frame;
  frame.reserve(13 + payload.size());
  frame.push_back(0x01);
  append_le(frame, subscription_id, 4);
  append_le(frame, timestamp_ns, 8);
  frame.append(reinterpret_cast<const char*>(payload.data()), payload.size());
  return frame;
}

std::string time_frame(std::uint64_t timestamp_ns) {
  std::string frame;
  frame.push_back(0x02);
  append_le(frame, timestamp_ns, 8);
  return frame;
}

ClientRequest parse_client_request(const std::string& text) {
  const json message = json::parse(text, nullptr, false);
  if (message.is_discarded()) throw ProtocolError("not JSON");
  if (!message.is_object()) throw ProtocolError("not a JSON object");
  const std::string op = string_field(message, "op");
  if (op == "subscribe") {
    Subscribe request;
    for (const json& item : array_field(message, "subscriptions")) {
      request.subscriptions.push_back(
          {id_field(object_item(item), "id"), id_field(item, "channelId")});
    }
    return request;
  }
  if (op == "unsubscribe") return Unsubscribe{id_array(message, "subscriptionIds")};
  if (op == "advertise") {
    ClientAdvertise request;
    for (const json& item : array_field(message, "channels")) {
      request.channels.push_back({id_field(object_item(item), "id"), string_field(item, "topic"),
                                  string_field(item, "encoding"),
                                  string_field(item, "schemaName")});
    }
    return request;
  }
  if (op == "unadvertise") return ClientUnadvertise{id_array(message, "channelIds")};
  throw ProtocolError("unsupported op '" + op + "'");
}

ClientMessage parse_client_message(const std::string& frame) {
  if (frame.empty()) throw ProtocolError("empty binary frame");
  if (static_cast<std::uint8_t>(frame[0]) != 0x01) {
    throw ProtocolError("unsupported binary opcode " +
                        std::to_string(static_cast<std::uint8_t>(frame[0])));
  }
  if (frame.size() < 5) throw ProtocolError("binary frame too short for a channel id");
  std::uint32_t channel = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    channel |= static_cast<std::uint32_t>(static_cast<std::uint8_t>(frame[1 + i])) << (8 * i);
  }
  return {channel, {reinterpret_cast<const std::uint8_t*>(frame.data()) + 5, frame.size() - 5}};
}

}  // namespace agnocast::foxglove
