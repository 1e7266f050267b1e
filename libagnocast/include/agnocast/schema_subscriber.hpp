// A polling subscriber for tools that do not know a topic's message type at
// compile time (agnocast-cli topic echo): it subscribes with the type the
// topic's endpoints registered in the kernel and reads messages through the
// schema they brought. Messages come from another process, so it also hands
// out the pool each one lives in, the only bytes a checked render may read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/node.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/schema_topic.hpp"

namespace agnocast {

// One taken message, held (the publisher cannot reuse its memory) until destroyed.
class SchemaMessage {
 public:
  SchemaMessage(const void* message, std::span<const std::byte> pool,
                detail::EntryReference* reference) noexcept;
  ~SchemaMessage();
  SchemaMessage(SchemaMessage&& other) noexcept;
  SchemaMessage& operator=(SchemaMessage&&) = delete;
  SchemaMessage(const SchemaMessage&) = delete;

  const void* data() const { return message_; }
  // The publisher's pool as mapped here, read-only; empty if the message is in none.
  std::span<const std::byte> readable() const { return pool_; }

 private:
  const void* message_;
  std::span<const std::byte> pool_;
  detail::EntryReference* reference_;
};

class SchemaSubscriber {
 public:
  // Throws TopicWithoutSchema, SchemaError when the registered schema is
  // invalid, and what creating a subscriber throws (AccessDenied, ...).
  SchemaSubscriber(Node& node, std::string_view topic, const QoS& qos);

  const Schema& schema() const { return topic_.schema; }
  const std::string& type_name() const { return topic_.type_name; }
  std::uint64_t type_hash() const { return topic_.type_hash; }
  const std::string& topic() const { return core_->topic(); }

  // The newest message not taken yet, or nullopt.
  std::optional<SchemaMessage> take();

 private:
  SchemaTopic topic_;
  std::unique_ptr<detail::PollingCore> core_;
};

}  // namespace agnocast
