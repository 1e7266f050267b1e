#pragma once

#include <functional>
#include <memory>
#include <utility>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/ipc_shared_ptr.hpp"

namespace agnocast {

// Runs its callback from an executor for every message published on its topic.
template <class T>
class Subscription : public detail::SubscriptionBase {
 public:
  using Callback = std::function<void(const ipc_shared_ptr<const T>&)>;

  Subscription(std::shared_ptr<detail::NodeState> node, std::string_view topic, const QoS& qos,
               Callback callback)
      : SubscriptionBase(std::move(node), topic, qos, detail::message_type_of<T>()),
        callback_(std::move(callback)) {}

  const std::string& get_topic_name() const { return topic(); }

 private:
  void deliver(const void* message, detail::EntryReference* reference) override {
    const auto pointer = detail::MessageAccess::received(static_cast<const T*>(message), reference);
    callback_(pointer);
  }

  Callback callback_;
};

// Never woken: the caller asks for the newest message with take_data().
template <class T>
class PollingSubscriber {
 public:
  PollingSubscriber(std::shared_ptr<detail::NodeState> node, std::string_view topic, const QoS& qos)
      : core_(std::move(node), topic, qos, detail::message_type_of<T>()) {}

  // The newest message not taken yet; empty when nothing new arrived.
  ipc_shared_ptr<const T> take_data() {
    const detail::TakenEntry taken = core_.take();
    if (!taken.message) return {};
    return detail::MessageAccess::received(static_cast<const T*>(taken.message), taken.reference);
  }

  const std::string& get_topic_name() const { return core_.topic(); }
  std::uint32_t id() const { return core_.id(); }

 private:
  detail::PollingCore core_;
};

}  // namespace agnocast
