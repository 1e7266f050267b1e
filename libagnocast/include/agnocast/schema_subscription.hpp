// A subscription for tools that do not know a topic's message type at compile
// time and must see every message, not only the newest (agnocast-cli bag
// record): it subscribes with the type and schema the topic's endpoints
// registered in the kernel, like SchemaSubscriber, and hands each received
// message, held only for the callback's duration, to a callback. No executor
// runs it: the owner waits on wait_fd() and calls receive().
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/message_info.hpp"
#include "agnocast/node.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/schema_subscriber.hpp"

namespace agnocast {

class SchemaSubscription {
 public:
  // The message, readable within message.readable(), is released when the callback returns.
  using Callback = std::function<void(const SchemaMessage& message, const MessageInfo& info)>;

  // Throws TopicWithoutSchema, SchemaError when the registered schema is
  // invalid, and what creating a subscription throws (AccessDenied, ...).
  SchemaSubscription(Node& node, std::string_view topic, const QoS& qos, Callback callback);
  ~SchemaSubscription();
  SchemaSubscription(const SchemaSubscription&) = delete;
  SchemaSubscription& operator=(const SchemaSubscription&) = delete;

  const Schema& schema() const { return topic_.schema; }
  // The schema as the kernel holds it.
  const std::vector<std::uint8_t>& schema_blob() const { return topic_.blob; }
  const std::string& type_name() const { return topic_.type_name; }
  std::uint64_t type_hash() const { return topic_.type_hash; }
  const std::string& topic() const;
  // The subscriber's id on the topic (agnocast-cli topic info lists its drops by it).
  std::uint32_t id() const;

  // Readable (poll) when messages wait.
  int wait_fd() const;
  // Runs the callback on every waiting message, oldest first; returns how many.
  std::size_t receive();

 private:
  class Core;
  SchemaTopic topic_;
  std::shared_ptr<Core> core_;
};

}  // namespace agnocast
