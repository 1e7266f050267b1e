#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/detail/loan.hpp"
#include "agnocast/heap_scope.hpp"
#include "agnocast/ipc_shared_ptr.hpp"

namespace agnocast {

template <class T>
class Publisher {
  static_assert(!std::is_polymorphic_v<T>,
                "agnocast messages cannot have virtual functions: vtable addresses differ "
                "between processes");
  static_assert(!std::is_const_v<T>, "publish a non-const message type");

 public:
  Publisher(std::shared_ptr<detail::NodeState> node, std::string_view topic, const QoS& qos)
      : core_(std::move(node), topic, qos, detail::message_type_of<T>()) {}

  // A default-constructed T in this process's shared pool, for you to fill in.
  // For a heap message (AGNOCAST_HEAP_MESSAGE), this thread allocates in the
  // pool until the loan is published or dropped (heap_scope.hpp).
  ipc_shared_ptr<T> borrow_loaned_message() {
    return detail::MessageAccess::loan(detail::borrow_loan<T>());
  }

  // Zero-copy: hands the loan to every subscriber. message is empty afterwards.
  void publish(ipc_shared_ptr<T>&& message) {
    T* loaned = detail::loan_to_send(
        message, "publish needs a message from borrow_loaned_message() not yet published");
    core_.publish(loaned, detail::published_bytes(loaned, sizeof(T)));
  }

  const std::string& get_topic_name() const { return core_.topic(); }
  std::uint32_t id() const { return core_.id(); }

  // Live subscribers of the topic, in every process (polling ones included).
  std::size_t get_subscription_count() const { return core_.subscription_count(); }
  // Waits until the topic has at least count subscribers: true then, false
  // once timeout has passed without.
  template <class Rep, class Period>
  bool wait_for_subscribers(std::size_t count, std::chrono::duration<Rep, Period> timeout) const {
    return core_.wait_for_subscribers(
        count, std::chrono::duration_cast<std::chrono::nanoseconds>(timeout));
  }

 private:
  detail::PublisherCore core_;
};

}  // namespace agnocast
