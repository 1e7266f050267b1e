// Non-template cores behind Publisher<T>, Subscription<T> and
// PollingSubscriber<T>; the templates only add the message type.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "agnocast/detail/message.hpp"
#include "agnocast/detail/waitable.hpp"
#include "agnocast/message_info.hpp"
#include "agnocast/message_traits.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/subscription_options.hpp"

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

// Applications may not use the topics that carry services (<agnocast/naming.hpp>).
enum class TopicUse { application, service_carrier };

// Where a published message goes: to every subscriber, or to to_subscriber
// alone (ENXIO when it is gone); no_drop refuses it (EAGAIN) rather than
// dropping a full subscriber's oldest, and (EPIPE) when no subscriber would
// get it. Services use both; a topic's publishers use neither.
struct ServiceRoute {
  std::optional<std::uint32_t> to_subscriber;
  bool no_drop = false;
};

class PublisherCore {
 public:
  PublisherCore(std::shared_ptr<NodeState> node, std::string_view topic, const QoS& qos,
                const MessageType& type, TopicUse use = TopicUse::application);
  ~PublisherCore();
  PublisherCore(const PublisherCore&) = delete;
  PublisherCore& operator=(const PublisherCore&) = delete;

  // Takes ownership of a loaned message: publishes it and wakes subscribers.
  void publish(void* message, std::size_t bytes);
  // The same along a service's route; a refusal frees the message and throws.
  void publish(void* message, std::size_t bytes, const ServiceRoute& route);
  const std::string& topic() const;
  std::uint32_t id() const;
  // Live subscribers of the topic, in every process.
  std::size_t subscription_count() const;
  // True as soon as the topic has at least count subscribers; false after timeout.
  bool wait_for_subscribers(std::size_t count, std::chrono::nanoseconds timeout) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A message this process now holds, with a reference counting one holder.
struct TakenEntry {
  const void* message = nullptr;
  EntryReference* reference = nullptr;
};

// Live publishers of a topic, in every process.
std::size_t publisher_count(const std::string& topic);

class PollingCore {
 public:
  PollingCore(std::shared_ptr<NodeState> node, std::string_view topic, const QoS& qos,
              const MessageType& type, const SubscriptionOptions& options = {});
  ~PollingCore();
  PollingCore(const PollingCore&) = delete;
  PollingCore& operator=(const PollingCore&) = delete;

  // The newest message not taken yet, or an empty TakenEntry.
  TakenEntry take_new();
  // The newest message not taken yet, else the one taken last (again); empty
  // only before the first message.
  TakenEntry take_latest();
  const std::string& topic() const;
  std::uint32_t id() const;

 private:
  bool take_newer();

  struct State;
  std::unique_ptr<State> state_;
};

class SubscriptionBase : public Waitable {
 public:
  ~SubscriptionBase() override;

  const std::string& topic() const;
  std::uint32_t id() const;
  // The notification queue this subscription owns, e.g. "/chatter@1".
  const std::string& queue_name() const;
  int queue_fd() const;
  // Drains the queue, receives every waiting message and runs the callback
  // on each, oldest first; returns how many ran.
  std::size_t handle_wakeup();

  int wait_fd() const override { return queue_fd(); }
  void execute() override { handle_wakeup(); }
  // The one-shot timer that bounds how long releases wait for the next
  // wake-up's receive; readable once expired, when release_deferred() (run by
  // the executor) releases them.
  int release_timer_fd() const;
  void release_deferred();

 protected:
  SubscriptionBase(std::shared_ptr<NodeState> node, std::string_view topic, const QoS& qos,
                   const MessageType& type, const SubscriptionOptions& options,
                   TopicUse use = TopicUse::application);
  // Must take ownership of reference (count one) even when it throws.
  virtual void deliver(const void* message, EntryReference* reference, const MessageInfo& info) = 0;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The group a new callback of the node joins: the requested one, else the node's default.
std::shared_ptr<CallbackGroup> group_or_default(const NodeState& node,
                                                std::shared_ptr<CallbackGroup> requested);
// Makes a new subscription or timer visible to the executors that spin its node.
void register_waitable(NodeState& node, const std::shared_ptr<Waitable>& waitable);

}  // namespace agnocast::detail
