#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "agnocast/callback_group.hpp"
#include "agnocast/heap_scope.hpp"
#include "agnocast/message_traits.hpp"
#include "agnocast/publisher.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/service.hpp"
#include "agnocast/subscription.hpp"
#include "agnocast/subscription_options.hpp"
#include "agnocast/timer.hpp"

namespace agnocast {

// A named group of publishers, subscriptions and timers; the name is the label
// the kernel module and agnocast-cli show. Executors spin nodes.
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
    if constexpr (HeapMessage<T>) detail::require_heap_hook(message_traits<T>::type_name);
    return std::make_shared<Publisher<T>>(state_, topic, qos);
  }

  // callback takes `const ipc_shared_ptr<const T>&` or `const T&`, either
  // optionally followed by `const MessageInfo&`.
  template <class T, class Callback>
  std::shared_ptr<Subscription<T>> create_subscription(std::string_view topic, const QoS& qos,
                                                       Callback&& callback,
                                                       SubscriptionOptions options = {}) {
    static_assert(Publishable<T>, AGNOCAST_PUBLISHABLE_RULE);
    auto adapted = detail::adapt_callback<T>(std::forward<Callback>(callback));
    options.callback_group = detail::group_or_default(*state_, std::move(options.callback_group));
    auto subscription =
        std::make_shared<Subscription<T>>(state_, topic, qos, std::move(adapted), options);
    detail::register_waitable(*state_, subscription);
    return subscription;
  }

  // options.callback_group does not apply: a polling subscriber has no callback.
  template <class T>
  std::shared_ptr<PollingSubscriber<T>> create_polling_subscriber(
      std::string_view topic, const QoS& qos, const SubscriptionOptions& options = {}) {
    static_assert(Publishable<T>, AGNOCAST_PUBLISHABLE_RULE);
    return std::make_shared<PollingSubscriber<T>>(state_, topic, qos, options);
  }

  // Serves a service name: callback takes (const ipc_shared_ptr<const
  // Srv::Request>&, ipc_shared_ptr<Srv::Response>&) and fills the response,
  // or, deferred, (std::shared_ptr<Service<Srv>>, RequestId,
  // ipc_shared_ptr<const Srv::Request>) and answers later with
  // send_response(). qos.depth(): the requests that may wait for the server
  // before further ones are refused (RequestRejected at the client).
  // Throws ServiceExists when the name has a server already.
  template <ServiceType Srv, class Callback>
  std::shared_ptr<Service<Srv>> create_service(std::string_view name, Callback&& callback,
                                               const QoS& qos = QoS(service_queue_depth_default),
                                               std::shared_ptr<CallbackGroup> group = nullptr) {
    using Request = typename Srv::Request;
    using Response = typename Srv::Response;
    static_assert(Publishable<Request> && Publishable<Response>, AGNOCAST_PUBLISHABLE_RULE);
    SubscriptionOptions options;
    options.callback_group = detail::group_or_default(*state_, std::move(group));
    std::shared_ptr<Service<Srv>> service;
    if constexpr (std::is_invocable_v<Callback&, const ipc_shared_ptr<const Request>&,
                                      ipc_shared_ptr<Response>&>) {
      service = std::make_shared<Service<Srv>>(
          state_, name, qos, typename Service<Srv>::Callback(std::forward<Callback>(callback)),
          options);
    } else {
      static_assert(
          std::is_invocable_v<Callback&, std::shared_ptr<Service<Srv>>, RequestId,
                              ipc_shared_ptr<const Request>>,
          "agnocast: a service callback takes (const ipc_shared_ptr<const "
          "Srv::Request>&, ipc_shared_ptr<Srv::Response>&), or, to answer later, "
          "(std::shared_ptr<Service<Srv>>, RequestId, ipc_shared_ptr<const Srv::Request>)");
      service = std::make_shared<Service<Srv>>(
          state_, name, qos,
          typename Service<Srv>::DeferredCallback(std::forward<Callback>(callback)), options);
    }
    detail::register_waitable(*state_, service);
    return service;
  }

  // Calls a service name; qos.depth() bounds the requests in flight.
  template <ServiceType Srv>
  std::shared_ptr<Client<Srv>> create_client(std::string_view name,
                                             const QoS& qos = QoS(client_in_flight_default),
                                             std::shared_ptr<CallbackGroup> group = nullptr) {
    SubscriptionOptions options;
    options.callback_group = detail::group_or_default(*state_, std::move(group));
    auto client = std::make_shared<Client<Srv>>(state_, name, qos, options);
    detail::register_waitable(*state_, client);
    return client;
  }

  // Calls callback every period (steady clock) from the executor spinning
  // this node; group empty: the node's default group.
  template <class Rep, class Period>
  std::shared_ptr<Timer> create_wall_timer(std::chrono::duration<Rep, Period> period,
                                           std::function<void()> callback,
                                           std::shared_ptr<CallbackGroup> group = nullptr) {
    return create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(period),
                        std::move(callback), std::move(group));
  }

  std::shared_ptr<CallbackGroup> create_callback_group(CallbackGroupType type);
  // MutuallyExclusive: without groups of their own, a node's callbacks never overlap.
  const std::shared_ptr<CallbackGroup>& get_default_callback_group() const;

  const std::shared_ptr<detail::NodeState>& state() const { return state_; }

 private:
  std::shared_ptr<Timer> create_timer(std::chrono::nanoseconds period,
                                      std::function<void()> callback,
                                      std::shared_ptr<CallbackGroup> group);

  std::shared_ptr<detail::NodeState> state_;
};

}  // namespace agnocast
