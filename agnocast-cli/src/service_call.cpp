// agnocast-cli service call NAME TYPE [JSON] [--timeout S] [--json]
#include "service_call.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <thread>

#include "agnocast/errors.hpp"
#include "agnocast/json_to_cdr.hpp"
#include "agnocast/message_render.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/node.hpp"
#include "agnocast/schema_client.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

// Nothing wakes a caller when a service appears: look this often.
constexpr double service_poll_interval_s = 0.02;

std::chrono::nanoseconds nanoseconds_of(double seconds) {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(std::max(seconds, 0.0) * 1e9));
}

CliError no_server(const ServiceCallOptions& options) {
  return CliError("service '" + options.service + "' has no server (waited " +
                  seconds_text(options.timeout_s) +
                  " s); `agnocast-cli service list` shows the "
                  "services there are");
}

class SystemServiceBackend final : public ServiceBackend {
 public:
  std::optional<ServiceTypes> find_types(const std::string& service) override {
    return find_service_types(service);
  }

  CallOutcome call(const std::string& service, const ServiceTypes& types,
                   std::span<const std::uint8_t> request, double timeout_s,
                   const Show& show) override {
    const auto deadline = std::chrono::steady_clock::now() + nanoseconds_of(timeout_s);
    const auto remaining = [&] { return deadline - std::chrono::steady_clock::now(); };
    // A node of its own, so that `service info` names the caller.
    Node node("agnocast_cli_service_call");
    SchemaClient client(node, service, types);
    if (!client.wait_for_service(remaining())) return CallOutcome::no_server;
    const std::optional<SchemaMessage> response = client.call_cdr(request, remaining());
    if (!response) return CallOutcome::timed_out;
    show(response->data(), response->readable());
    return CallOutcome::answered;
  }

  double now_seconds() override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  void sleep_seconds(double seconds) override {
    std::this_thread::sleep_for(nanoseconds_of(seconds));
  }
};

}  // namespace

ServiceBackend& system_service_backend() {
  static SystemServiceBackend backend;
  return backend;
}

int service_call(ServiceBackend& backend, const ServiceCallOptions& options, std::ostream& out) {
  // What is wrong whatever the service is: said at once, not after waiting for it.
  if (normalized_service_type(options.type).empty()) {
    throw InputError("'" + options.type +
                     "' is no service type; write it as pkg/srv/Name, "
                     "e.g. std_srvs/srv/SetBool");
  }
  if (const std::string problem = json_syntax_problem(options.request); !problem.empty()) {
    throw InputError("the request: " + problem);
  }

  const double start = backend.now_seconds();
  const auto left = [&] { return options.timeout_s - (backend.now_seconds() - start); };
  std::optional<ServiceTypes> types = backend.find_types(options.service);
  while (!types) {
    if (left() <= 0) throw no_server(options);
    backend.sleep_seconds(std::min(service_poll_interval_s, left()));
    types = backend.find_types(options.service);
  }
  std::vector<std::uint8_t> request;
  try {
    require_service_type(*types, options.service, options.type);
    request = json_to_cdr(options.request, types->request.schema);
  } catch (const TypeMismatch& error) {
    throw InputError(error.what());
  } catch (const JsonInputError& error) {
    throw InputError(std::string("the request: ") + error.what());
  }

  // The response comes from another process: render it checked, within its pool.
  const ServiceBackend::Show show = [&](const void* response, std::span<const std::byte> readable) {
    const RenderOptions render{.readable = readable};
    if (options.json) {
      out << render_message_json(response, types->response.schema, render) << '\n';
    } else {
      out << render_message_text(response, types->response.schema, render);
    }
  };
  switch (backend.call(options.service, *types, request, std::max(left(), 0.0), show)) {
    case CallOutcome::answered:
      return exit_success;
    case CallOutcome::no_server:
      throw no_server(options);
    case CallOutcome::timed_out:
      break;
  }
  throw CliError("service '" + options.service + "' did not answer within " +
                 seconds_text(options.timeout_s) + " s");
}

void set_service_call_command(CLI::App& service, Context& context) {
  auto options = std::make_shared<ServiceCallOptions>();
  CLI::App* call = service.add_subcommand(
      "call", "Call a service with a request written as JSON and print the response");
  call->add_option("NAME", options->service, "Service name, e.g. /arm/enable")
      ->required()
      ->check(CLI::Validator([](std::string& name) { return service_name_problem(name); }, "NAME",
                             "service name"));
  call->add_option("TYPE", options->type, "Service type, e.g. std_srvs/srv/SetBool")->required();
  call->add_option("JSON", options->request,
                   "The request's fields as a JSON object, e.g. '{\"data\": true}'; fields left "
                   "out are zero (default: {})");
  call->add_option("--timeout", options->timeout_s,
                   "Give up after S seconds (exit 1) without a server or an answer (default 5)")
      ->check(CLI::PositiveNumber);
  bind_command(*call, context, {.stream = [&context, options](std::ostream& out) {
    options->json = context.json;
    return service_call(system_service_backend(), *options, out);
  }});
  call->get_option("--json")->description("Print the response as one JSON object");
}

}  // namespace agnocast::cli
