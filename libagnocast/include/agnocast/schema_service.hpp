// A service server for bindings and tools that know the service's types only
// from their schemas (Python's services): each request is read in place in
// the client's pool, a SchemaMessage, and the response goes back through its
// Responder as a loan the handler built or as XCDR1 bytes. Same protocol, one server per name and
// errors as Service<Srv> (<agnocast/service.hpp>).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "agnocast/callback_group.hpp"
#include "agnocast/detail/service_cores.hpp"
#include "agnocast/node.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/schema_service_types.hpp"
#include "agnocast/schema_subscriber.hpp"
#include "agnocast/service.hpp"

namespace agnocast {

class SchemaService {
  class Core;

 public:
  // Answers one request, now or later, from any thread; while kept, it keeps
  // the server's endpoints (as the deferred callback's Service<Srv> does).
  class Responder {
   public:
    const RequestId& id() const { return id_; }
    // Takes ownership of a loan of the response type (detail::allocate_message(),
    // built as the response's schema lays it out) and sends it to the client
    // that asked; a client that is gone does not get it (counted in failures()).
    void send(void* response, std::size_t bytes) const;
    // The same for the response whose XCDR1 bytes are `cdr`; throws
    // cdr::Error, naming the field and sending nothing, when they are no
    // response of the type.
    void send_cdr(std::span<const std::uint8_t> cdr) const;

   private:
    friend class SchemaService;
    Responder(std::shared_ptr<Core> core, const RequestId& id) : core_(std::move(core)), id_(id) {}
    std::shared_ptr<Core> core_;
    RequestId id_;
  };

  // Runs for each request, from the executor spinning the node: the request
  // in place, readable only within request.readable() (the client's pool:
  // every pointer and length in it is the client's to write), and how to
  // answer it. A request nobody answers never is.
  using Callback = std::function<void(SchemaMessage request, Responder responder)>;

  // Throws SchemaError when the response's containers are laid out otherwise
  // than this process lays them out, ServiceExists when the name has a
  // server already, TypeMismatch when its endpoints registered other types,
  // and what creating a subscription throws (AccessDenied, ...).
  SchemaService(Node& node, std::string_view service, ServiceTypes types, Callback callback,
                const QoS& qos = QoS(service_queue_depth_default),
                std::shared_ptr<CallbackGroup> group = nullptr);
  // Once no Responder is left either, tells every client that what it has
  // not had answered never will be.
  ~SchemaService();
  SchemaService(const SchemaService&) = delete;
  SchemaService& operator=(const SchemaService&) = delete;

  const ServiceTypes& types() const;
  const std::string& service_name() const;
  std::uint64_t calls() const;     // requests handed to the callback
  std::uint64_t failures() const;  // requests refused and responses not delivered

 private:
  std::shared_ptr<Core> core_;
};

}  // namespace agnocast
