#include "agnocast/schema_subscriber.hpp"

#include <utility>

#include "agnocast/inspect.hpp"
#include "runtime.hpp"

namespace agnocast {

SchemaMessage::SchemaMessage(const void* message, std::span<const std::byte> pool,
                             detail::EntryReference* reference) noexcept
    : message_(message), pool_(pool), reference_(reference) {}

SchemaMessage::~SchemaMessage() {
  if (reference_) detail::release(reference_);
}

SchemaMessage::SchemaMessage(SchemaMessage&& other) noexcept
    : message_(other.message_),
      pool_(other.pool_),
      reference_(std::exchange(other.reference_, nullptr)) {}

SchemaSubscriber::SchemaSubscriber(Node& node, std::string_view topic, const QoS& qos) {
  const std::string name(topic);
  const std::optional<TopicInfo> info = topic_info(name);
  if (!info) {
    throw TopicWithoutSchema("no publisher or subscriber uses topic '" + name +
                             "', so its message type is unknown");
  }
  std::optional<std::vector<std::uint8_t>> blob = topic_schema(name);
  if (!blob || blob->empty()) {
    throw TopicWithoutSchema(
        "topic '" + name + "' (type " + info->type_name +
        ") has no schema: its endpoints were built with a type that does not describe its "
        "fields; declare it with AGNOCAST_MESSAGE or generate it with agnocast-msggen and "
        "rebuild the publisher");
  }
  type_name_ = info->type_name;
  type_hash_ = info->type_hash;
  blob_ = std::move(*blob);
  schema_ = parse_schema(blob_);
  core_ = std::make_unique<detail::PollingCore>(node.state(), topic, qos,
                                                detail::MessageType{type_name_, type_hash_, blob_});
}

std::optional<SchemaMessage> SchemaSubscriber::take() {
  const detail::TakenEntry taken = core_->take_new();
  if (!taken.message) return std::nullopt;
  return SchemaMessage(taken.message, detail::Runtime::get().pool_holding(taken.message),
                       taken.reference);
}

}  // namespace agnocast
