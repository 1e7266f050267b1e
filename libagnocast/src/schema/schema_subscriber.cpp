#include "agnocast/schema_subscriber.hpp"

#include <utility>

#include "kernel/runtime.hpp"

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

SchemaSubscriber::SchemaSubscriber(Node& node, std::string_view topic, const QoS& qos)
    : topic_(resolve_schema_topic(topic)),
      core_(
          std::make_unique<detail::PollingCore>(node.state(), topic, qos, topic_.message_type())) {}

std::optional<SchemaMessage> SchemaSubscriber::take() {
  const detail::TakenEntry taken = core_->take_new();
  if (!taken.message) return std::nullopt;
  return SchemaMessage(taken.message, detail::Runtime::get().pool_holding(taken.message),
                       taken.reference);
}

}  // namespace agnocast
