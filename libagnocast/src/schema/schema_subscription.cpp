#include "agnocast/schema_subscription.hpp"

#include <utility>

#include "kernel/runtime.hpp"

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
                                       Callback callback)
    : topic_(resolve_schema_topic(topic)),
      core_(std::make_shared<Core>(node, topic, qos, topic_.message_type(), std::move(callback))) {}

SchemaSubscription::~SchemaSubscription() = default;

const std::string& SchemaSubscription::topic() const { return core_->topic(); }
std::uint32_t SchemaSubscription::id() const { return core_->id(); }
int SchemaSubscription::wait_fd() const { return core_->queue_fd(); }
std::size_t SchemaSubscription::receive() { return core_->handle_wakeup(); }

}  // namespace agnocast
