// What a new publisher or subscriber asks of the kernel, validated once for all.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "agnocast/qos.hpp"

namespace agnocast::detail {

struct MessageType;
enum class TopicUse;

enum class EndpointKind { publisher, callback_subscriber, polling_subscriber };

struct EndpointRequest {
  std::string topic;
  std::string node;
  std::uint32_t depth = 1;
  bool transient_local = false;
  bool polling = false;
  bool ignore_local = false;  // subscribers: skip messages of this process (kernel-filtered)
  // Callback subscribers: one notification between two receives, however many
  // entries arrive meanwhile (the wake-up receives until nothing remains).
  bool wake_once = false;
  // The message type: the topic's must be the same (TypeMismatch otherwise).
  std::string type_name;
  std::uint64_t type_hash = 0;
  std::span<const std::uint8_t> schema;  // kept by the kernel for tools; may be empty
};

// Validates topic, depth and type name against <agnocast/limits.hpp>
// (std::invalid_argument naming the rule) and fills the request.
EndpointRequest make_endpoint_request(std::string_view node, std::string_view topic, const QoS& qos,
                                      EndpointKind kind, const MessageType& type, TopicUse use);

}  // namespace agnocast::detail
