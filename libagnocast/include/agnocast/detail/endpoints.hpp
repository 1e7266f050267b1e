// Non-template cores behind Publisher<T>, Subscription<T> and
// PollingSubscriber<T>; the templates only add the message type.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "agnocast/detail/message.hpp"
#include "agnocast/message_traits.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/schema.hpp"

namespace agnocast::detail {

struct NodeState;  // the node's name and its subscriptions, for executors

// What an endpoint tells the kernel about its message type: a topic carries
// one type, and tools decode its messages from the schema.
struct MessageType {
  std::string_view name;
  std::uint64_t hash = 0;
  std::span<const std::uint8_t> schema;
};

template <Publishable T>
MessageType message_type_of() {
  return MessageType{message_traits<T>::type_name, message_traits<T>::type_hash, schema_of<T>()};
}

class PublisherCore {
 public:
  PublisherCore(std::shared_ptr<NodeState> node, std::string_view topic, const QoS& qos,
                const MessageType& type);
  ~PublisherCore();
  PublisherCore(const PublisherCore&) = delete;
  PublisherCore& operator=(const PublisherCore&) = delete;

  // Takes ownership of a loaned message: publishes it and wakes subscribers.
  void publish(void* message, std::size_t bytes);
  const std::string& topic() const;
  std::uint32_t id() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A message this process now holds, with a reference counting one holder.
struct TakenEntry {
  const void* message = nullptr;
  EntryReference* reference = nullptr;
};

class PollingCore {
 public:
  PollingCore(std::shared_ptr<NodeState> node, std::string_view topic, const QoS& qos,
              const MessageType& type);
  ~PollingCore();
  PollingCore(const PollingCore&) = delete;
  PollingCore& operator=(const PollingCore&) = delete;

  // The newest message not taken yet, or an empty TakenEntry.
  TakenEntry take();
  const std::string& topic() const;
  std::uint32_t id() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

class SubscriptionBase {
 public:
  virtual ~SubscriptionBase();
  SubscriptionBase(const SubscriptionBase&) = delete;
  SubscriptionBase& operator=(const SubscriptionBase&) = delete;

  const std::string& topic() const;
  std::uint32_t id() const;
  // The notification queue this subscription owns, e.g. "/chatter@1".
  const std::string& queue_name() const;
  int queue_fd() const;
  std::uint64_t key() const;  // unique in the process, for executors
  // Drains the queue, receives every waiting message and runs the callback
  // on each, oldest first; returns how many ran.
  std::size_t handle_wakeup();

 protected:
  SubscriptionBase(std::shared_ptr<NodeState> node, std::string_view topic, const QoS& qos,
                   const MessageType& type);
  // Must take ownership of reference (count one) even when it throws.
  virtual void deliver(const void* message, EntryReference* reference) = 0;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Makes a new subscription visible to the executors that spin its node.
void register_subscription(NodeState& node, const std::shared_ptr<SubscriptionBase>& subscription);

}  // namespace agnocast::detail
