#pragma once

#include <functional>
#include <memory>
#include <type_traits>
#include <utility>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/ipc_shared_ptr.hpp"
#include "agnocast/message_info.hpp"
#include "agnocast/subscription_options.hpp"

namespace agnocast {

namespace detail {

template <class>
inline constexpr bool unsupported_callback = false;

// Turns any of the accepted callback forms into the one Subscription stores.
template <class T, class F>
auto adapt_callback(F&& callback) {
  using Pointer = const ipc_shared_ptr<const T>&;
  using Callback = std::decay_t<F>;
  using Stored = std::function<void(Pointer, const MessageInfo&)>;
  if constexpr (std::is_invocable_v<Callback&, Pointer, const MessageInfo&>) {
    return Stored(std::forward<F>(callback));
  } else if constexpr (std::is_invocable_v<Callback&, Pointer>) {
    return Stored([f = Callback(std::forward<F>(callback))](
                      Pointer message, const MessageInfo&) mutable { f(message); });
  } else if constexpr (std::is_invocable_v<Callback&, const T&, const MessageInfo&>) {
    return Stored([f = Callback(std::forward<F>(callback))](
                      Pointer message, const MessageInfo& info) mutable { f(*message, info); });
  } else if constexpr (std::is_invocable_v<Callback&, const T&>) {
    return Stored([f = Callback(std::forward<F>(callback))](
                      Pointer message, const MessageInfo&) mutable { f(*message); });
  } else {
    static_assert(unsupported_callback<F>,
                  "agnocast: a subscription callback must take `const "
                  "agnocast::ipc_shared_ptr<const Msg>&` or `const Msg&`, optionally followed by "
                  "`const agnocast::MessageInfo&`");
    return Stored();
  }
}

}  // namespace detail

// Runs its callback from an executor for every message published on its topic.
template <class T>
class Subscription : public detail::SubscriptionBase {
 public:
  using Callback = std::function<void(const ipc_shared_ptr<const T>&, const MessageInfo&)>;

  Subscription(std::shared_ptr<detail::NodeState> node, std::string_view topic, const QoS& qos,
               Callback callback, const SubscriptionOptions& options = {})
      : SubscriptionBase(std::move(node), topic, qos, detail::message_type_of<T>(), options),
        callback_(std::move(callback)) {}

  const std::string& get_topic_name() const { return topic(); }
  // Live publishers of the topic, in every process.
  std::size_t get_publisher_count() const { return detail::publisher_count(topic()); }

 private:
  void deliver(const void* message, detail::EntryReference* reference,
               const MessageInfo& info) override {
    const auto pointer = detail::MessageAccess::received(static_cast<const T*>(message), reference);
    callback_(pointer, info);
  }

  Callback callback_;
};

// Never woken: the caller asks for the newest message when it wants one.
template <class T>
class PollingSubscriber {
 public:
  PollingSubscriber(std::shared_ptr<detail::NodeState> node, std::string_view topic, const QoS& qos,
                    const SubscriptionOptions& options = {})
      : core_(std::move(node), topic, qos, detail::message_type_of<T>(), options) {}

  // The newest message within the depth; the same one again when nothing
  // newer arrived since; empty only before the first message.
  ipc_shared_ptr<const T> take_data() { return pointer_to(core_.take_latest()); }
  // Only a message not taken before (the newest such), else empty.
  ipc_shared_ptr<const T> take_new_data() { return pointer_to(core_.take_new()); }

  const std::string& get_topic_name() const { return core_.topic(); }
  std::uint32_t id() const { return core_.id(); }
  // Live publishers of the topic, in every process.
  std::size_t get_publisher_count() const { return detail::publisher_count(core_.topic()); }

 private:
  static ipc_shared_ptr<const T> pointer_to(const detail::TakenEntry& taken) {
    if (!taken.message) return {};
    return detail::MessageAccess::received(static_cast<const T*>(taken.message), taken.reference);
  }

  detail::PollingCore core_;
};

}  // namespace agnocast
