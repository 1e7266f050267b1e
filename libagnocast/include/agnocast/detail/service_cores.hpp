// Non-template cores behind Service<Srv> and Client<Srv> (service.hpp); the
// templates only add the request and response types. A service rides two
// topics (<agnocast/naming.hpp>): requests go, without ever being dropped, to
// the server's one subscriber; each response goes to the one client that asked.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "agnocast/detail/endpoints.hpp"

namespace agnocast {

// Names one request: the client (its subscriber id on the service's reply
// topic) and the client's sequence number for it.
struct RequestId {
  std::uint32_t client = 0;
  std::uint64_t sequence = 0;

  bool operator==(const RequestId&) const = default;
};

}  // namespace agnocast

namespace agnocast::detail {

// A default-constructed response loan (allocate_message), for the word a
// stopping server sends every client.
using ResponseFactory = std::function<void*()>;

class ServiceCore : public SubscriptionBase {
 public:
  // Throws ServiceExists when the name has a server already.
  ServiceCore(std::shared_ptr<NodeState> node, std::string_view service, const QoS& qos,
              const MessageType& request_type, const MessageType& response_type,
              ResponseFactory empty_response, const SubscriptionOptions& options);
  // Tells every client that what it has not had answered never will be.
  ~ServiceCore() override;

  // Takes ownership of the loaned response and sends it to the client that
  // asked. A client that is gone, or whose reply queue is full, does not get
  // it (counted in failures(), never thrown).
  void send_response(const RequestId& id, void* response, std::size_t bytes);
  // Tells the client that asked that this request will not be answered (its
  // future throws ServiceUnavailable); a client that is gone is counted in
  // failures(), never thrown.
  void fail_request(const RequestId& id);
  const std::string& service_name() const;
  std::uint64_t calls() const;     // requests handed to the callback
  std::uint64_t failures() const;  // requests refused and responses not delivered

 protected:
  // Owns reference (count one) even when it throws.
  virtual void handle_request(const void* request, EntryReference* reference,
                              const RequestId& id) = 0;

 private:
  void deliver(const void* message, EntryReference* reference, const MessageInfo& info) final;
  // A response or a failure, loaned, to the client that asked.
  void send_reply(const RequestId& id, void* response, std::size_t bytes, ServiceStatus status);

  struct State;
  std::unique_ptr<State> state_;
};

// One request's way back to its caller. complete() runs once, from the
// executor or inside ClientCore::send(): with the response (its reference
// count one, now the call's), or with error. A call never completed (pruned,
// forgotten, its client destroyed) is only destroyed.
class PendingCall {
 public:
  virtual ~PendingCall() = default;
  virtual void complete(const void* response, EntryReference* reference,
                        std::exception_ptr error) = 0;
};

class ClientCore : public SubscriptionBase {
 public:
  // A PendingCall's complete() as a function.
  using Completion = std::function<void(const void* response, EntryReference* reference,
                                        std::exception_ptr error)>;

  // qos.depth() bounds the requests in flight.
  ClientCore(std::shared_ptr<NodeState> node, std::string_view service, const QoS& qos,
             const MessageType& request_type, const MessageType& response_type,
             const SubscriptionOptions& options);
  ~ClientCore() override;

  // Takes ownership of the loaned request. Throws TooManyRequests, with
  // nothing sent, when the in-flight bound is reached; every other failure
  // reaches the call.
  RequestId send(void* request, std::size_t bytes, std::unique_ptr<PendingCall> call);
  RequestId send(void* request, std::size_t bytes, Completion completion);
  bool service_is_ready() const;
  bool wait_for_service(std::chrono::nanoseconds timeout) const;
  // Forgets every pending request (their completions never run); returns how many.
  std::size_t prune_pending();
  // Forgets one pending request (its completion never runs); false when it
  // is not pending (answered, failed or forgotten already).
  bool forget(const RequestId& id);
  std::size_t pending() const;
  const std::string& service_name() const;

  struct State;

 private:
  void deliver(const void* message, EntryReference* reference, const MessageInfo& info) final;

  std::shared_ptr<State> state_;
};

}  // namespace agnocast::detail
