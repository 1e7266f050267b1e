#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "agnocast/message_traits.hpp"
#include "agnocast/publisher.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/subscription.hpp"

namespace agnocast {

// A named group of publishers and subscriptions; the name is the label the
// kernel module and agnocast-cli show. Executors spin nodes.
class Node {
 public:
  // name: printable ASCII, at most 127 characters (std::invalid_argument otherwise).
  explicit Node(std::string name);
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  const std::string& get_name() const;

  template <class T>
  std::shared_ptr<Publisher<T>> create_publisher(std::string_view topic, const QoS& qos) {
    static_assert(Publishable<T>, AGNOCAST_PUBLISHABLE_RULE);
    return std::make_shared<Publisher<T>>(state_, topic, qos);
  }

  template <class T, class Callback>
  std::shared_ptr<Subscription<T>> create_subscription(std::string_view topic, const QoS& qos,
                                                       Callback&& callback) {
    static_assert(Publishable<T>, AGNOCAST_PUBLISHABLE_RULE);
    auto subscription = std::make_shared<Subscription<T>>(
        state_, topic, qos, typename Subscription<T>::Callback(std::forward<Callback>(callback)));
    detail::register_subscription(*state_, subscription);
    return subscription;
  }

  template <class T>
  std::shared_ptr<PollingSubscriber<T>> create_polling_subscriber(std::string_view topic,
                                                                  const QoS& qos) {
    static_assert(Publishable<T>, AGNOCAST_PUBLISHABLE_RULE);
    return std::make_shared<PollingSubscriber<T>>(state_, topic, qos);
  }

  const std::shared_ptr<detail::NodeState>& state() const { return state_; }

 private:
  std::shared_ptr<detail::NodeState> state_;
};

}  // namespace agnocast
