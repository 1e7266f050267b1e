// agnocast-cli service call NAME TYPE [JSON] [--timeout S] [--json]: calls a
// service with a request written as JSON and prints the response as topic
// echo prints a message. The types come from the service's own topics (the
// kernel keeps each endpoint's schema), so any service type can be called.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <span>
#include <string>

#include "agnocast/schema_service_types.hpp"
#include "cli.hpp"

namespace agnocast::cli {

struct ServiceCallOptions {
  std::string service;
  std::string type;            // "pkg/srv/Name" or "pkg/Name"
  std::string request = "{}";  // the request's fields as JSON; left out ones are zero
  double timeout_s = 5.0;      // for the server to appear and to answer
  bool json = false;           // the response as one JSON object
};

// What a call came to, when it did not fail.
enum class CallOutcome { answered, no_server, timed_out };

// The live system behind service call, apart so that the command runs against a fake.
class ServiceBackend {
 public:
  // The response in place and the only bytes a reader may touch (the server's pool).
  using Show = std::function<void(const void* response, std::span<const std::byte> readable)>;

  virtual ~ServiceBackend() = default;
  // The types the service's two topics registered; nullopt while it has no endpoint.
  virtual std::optional<ServiceTypes> find_types(const std::string& service) = 0;
  // Sends the request (XCDR1) and shows the response while it is held,
  // waiting for a server and its answer up to timeout_s. Throws what a
  // failed call throws (ServiceUnavailable, RequestRejected).
  virtual CallOutcome call(const std::string& service, const ServiceTypes& types,
                           std::span<const std::uint8_t> request, double timeout_s,
                           const Show& show) = 0;
  virtual double now_seconds() = 0;  // monotonic
  virtual void sleep_seconds(double seconds) = 0;
};

// The real system: libagnocast's SchemaClient in a node of its own.
ServiceBackend& system_service_backend();

// Writes the response to `out` and returns 0. Throws InputError (exit 2) for
// JSON or a type the service does not take, CliError (exit 1) when no server
// answered within the timeout.
int service_call(ServiceBackend& backend, const ServiceCallOptions& options, std::ostream& out);

// A subcommand of `service`.
void set_service_call_command(CLI::App& service, Context& context);

}  // namespace agnocast::cli
