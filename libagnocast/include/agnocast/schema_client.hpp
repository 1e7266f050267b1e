// A service client for tools and bindings that know the service's types only
// from their schemas (agnocast-cli service call, Python): requests go as
// XCDR1 bytes, turned into the request in this process's pool, or as loans
// the caller built; each response is read in place in the server's pool, a
// SchemaMessage that a checked render (<agnocast/message_render.hpp>) prints.
// Same protocol, bounds and errors as Client<Srv> (<agnocast/service.hpp>).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "agnocast/callback_group.hpp"
#include "agnocast/detail/service_cores.hpp"
#include "agnocast/node.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/schema_service_types.hpp"
#include "agnocast/schema_subscriber.hpp"
#include "agnocast/service.hpp"

namespace agnocast {

class SchemaClient {
 public:
  // Runs once per request: with the response, or with the error a future of
  // Client<Srv> would throw (ServiceUnavailable, RequestRejected).
  using Completion =
      std::function<void(std::optional<SchemaMessage> response, std::exception_ptr error)>;

  // An executor spinning `node` delivers responses (in `group`, the node's
  // default when empty); call() needs none. qos.depth() bounds the requests in
  // flight. Throws SchemaError when the request's containers are laid out
  // otherwise than this process lays them out, TypeMismatch when the
  // service's endpoints registered other types, and what creating a client
  // throws (AccessDenied, ...).
  SchemaClient(Node& node, std::string_view service, ServiceTypes types,
               const QoS& qos = QoS(client_in_flight_default),
               std::shared_ptr<CallbackGroup> group = nullptr);
  ~SchemaClient();
  SchemaClient(const SchemaClient&) = delete;
  SchemaClient& operator=(const SchemaClient&) = delete;

  const ServiceTypes& types() const { return types_; }
  const std::string& service_name() const;

  bool service_is_ready() const;
  bool wait_for_service(std::chrono::nanoseconds timeout) const;

  // Sends a loan of the request type (detail::allocate_message(), built as
  // the request's schema lays it out), which it owns from here even when it
  // throws. Throws TooManyRequests, with nothing sent, at the in-flight bound;
  // every other failure reaches completion, which may run inside send().
  RequestId send(void* request, std::size_t bytes, Completion completion);
  // The same for the request whose XCDR1 bytes, encapsulation header
  // included, are `cdr`; throws cdr::Error, naming the field and sending
  // nothing, when they are no request of the type.
  RequestId send_cdr(std::span<const std::uint8_t> cdr, Completion completion);

  // Sends and waits up to `timeout` for the response, receiving it here when
  // no executor does (an executor spinning the node meanwhile is fine).
  // nullopt on timeout, the request then forgotten; throws what send() and
  // send_cdr() throw and what the completion would get.
  std::optional<SchemaMessage> call(void* request, std::size_t bytes,
                                    std::chrono::nanoseconds timeout);
  std::optional<SchemaMessage> call_cdr(std::span<const std::uint8_t> cdr,
                                        std::chrono::nanoseconds timeout);

  // Forgets one pending request (its completion never runs); false when it
  // is not pending.
  bool forget(const RequestId& id);
  // Forgets every pending request; returns how many.
  std::size_t prune_pending();
  std::size_t pending() const;

 private:
  ServiceTypes types_;
  std::shared_ptr<detail::ClientCore> core_;
};

}  // namespace agnocast
