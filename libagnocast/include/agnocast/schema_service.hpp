// A service server for bindings and tools that know the service's types only
// from their schemas (Python's services): each request is read in place in
// the client's pool, a SchemaMessage, and the response goes back as a loan
// the handler built or as XCDR1 bytes. Same protocol, one server per name and
// errors as Service<Srv> (<agnocast/service.hpp>).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
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

class SchemaService {
 public:
  // Runs for each request, from the executor spinning the node: the request
  // in place, readable only within request.readable() (the client's pool:
  // every pointer and length in it is the client's to write), and its id
  // for send_response(), now or later. A request nobody answers never is.
  using Callback = std::function<void(SchemaMessage request, const RequestId& id)>;

  // Throws SchemaError when the response's containers are laid out otherwise
  // than this process lays them out, ServiceExists when the name has a
  // server already, TypeMismatch when its endpoints registered other types,
  // and what creating a subscription throws (AccessDenied, ...).
  SchemaService(Node& node, std::string_view service, ServiceTypes types, Callback callback,
                const QoS& qos = QoS(service_queue_depth_default),
                std::shared_ptr<CallbackGroup> group = nullptr);
  // Tells every client that what it has not had answered never will be.
  ~SchemaService();
  SchemaService(const SchemaService&) = delete;
  SchemaService& operator=(const SchemaService&) = delete;

  const ServiceTypes& types() const { return types_; }
  const std::string& service_name() const;

  // Takes ownership of a loan of the response type (detail::allocate_message(),
  // built as the response's schema lays it out) and sends it to the client
  // `id` names; a client that is gone does not get it (counted in failures()).
  void send_response(const RequestId& id, void* response, std::size_t bytes);
  // The same for the response whose XCDR1 bytes are `cdr`; throws cdr::Error,
  // naming the field and sending nothing, when they are no response of the type.
  void send_response_cdr(const RequestId& id, std::span<const std::uint8_t> cdr);

  std::uint64_t calls() const;     // requests handed to the callback
  std::uint64_t failures() const;  // requests refused and responses not delivered

 private:
  class Core;
  ServiceTypes types_;
  std::shared_ptr<Core> core_;
};

}  // namespace agnocast
