#include "agnocast/schema_subscription.hpp"

#include <utility>

#include "agnocast/inspect.hpp"
#include "runtime.hpp"

namespace agnocast {

class SchemaSubscription::Core : public detail::SubscriptionBase {
 public:
  Core(Node& node, std::string_view topic, const QoS& qos, const detail::MessageType& type,
       Callback callback)
      : SubscriptionBase(node.state(), topic, qos, type, SubscriptionOptions{}),
        callback_(std::move(callback)) {}

 private:
  void deliver(const void* message, detail::EntryReference* reference,
               const MessageInfo& info) override {
    // Owns the reference from here on: released when `held` goes, even on a throw.
    const SchemaMessage held(message, detail::Runtime::get().pool_holding(message), reference);
    callback_(held, info);
  }

  Callback callback_;
};

SchemaSubscription::SchemaSubscription(Node& node, std::string_view topic, const QoS& qos,
                                       Callback callback) {
  const std::string name(topic);
  const std::optional<TopicInfo> info = topic_info(name);
  if (!info) {
    throw TopicWithoutSchema("no publisher or subscriber uses topic '" + name +
                             "', so its message type is unknown");
  }
  std::optional<std::vector<std::uint8_t>> blob = topic_schema(name);
  if (!blob || blob->empty()) {
    throw TopicWithoutSchema("topic '" + name + "' (type " + info->type_name +
                             ") has no schema: its endpoints were built with a type that does "
                             "not describe its fields; declare it with AGNOCAST_MESSAGE or "
                             "generate it with agnocast-msggen and rebuild the publisher");
  }
  type_name_ = info->type_name;
  type_hash_ = info->type_hash;
  blob_ = std::move(*blob);
  schema_ = parse_schema(blob_);
  core_ = std::make_shared<Core>(
      node, topic, qos, detail::MessageType{type_name_, type_hash_, blob_}, std::move(callback));
}

SchemaSubscription::~SchemaSubscription() = default;

const std::string& SchemaSubscription::topic() const { return core_->topic(); }
std::uint32_t SchemaSubscription::id() const { return core_->id(); }
int SchemaSubscription::wait_fd() const { return core_->queue_fd(); }
std::size_t SchemaSubscription::receive() { return core_->handle_wakeup(); }

}  // namespace agnocast
