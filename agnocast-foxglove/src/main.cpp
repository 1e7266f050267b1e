// agnocast-foxglove [--address A] [--port P] [--max-clients N] [--topics REGEX]
//                   [--status-file PATH]
// Exit 0 after SIGINT/SIGTERM/SIGHUP, 1 on a runtime error (cannot listen, no
// module, another server writes the status file), 2 on a usage error.
#include <arpa/inet.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <regex>
#include <string>

#include "agnocast/errors.hpp"
#include "agnocast/status.hpp"
#include "agnocast/version.hpp"
#include "agnocast_service/journal_log.hpp"
#include "protocol.hpp"
#include "server.hpp"

namespace {

constexpr char http_body[] =
    "agnocast-foxglove serves agnocast topics over the foxglove.websocket.v1 protocol.\n"
    "Open this address in Foxglove: Open connection, Foxglove WebSocket.\n";

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Serves every typed agnocast topic to Foxglove (foxglove.websocket.v1)",
               "agnocast-foxglove"};
  agnocast::foxglove::ServerOptions options;
  options.status_path = agnocast::foxglove_status_path;
  options.websocket.subprotocol = agnocast::foxglove::subprotocol;
  options.websocket.http_body = http_body;
  std::string topics;
  app.add_option("--address", options.websocket.address,
                 "IP address to listen on; anything but loopback lets every host that reaches "
                 "it read every topic")
      ->capture_default_str()
      ->check(
          [](const std::string& address) {
            unsigned char bytes[16];
            const bool ip = ::inet_pton(AF_INET, address.c_str(), bytes) == 1 ||
                            ::inet_pton(AF_INET6, address.c_str(), bytes) == 1;
            return ip ? std::string() : "'" + address + "' is not an IPv4 or IPv6 address";
          },
          "IP");
  app.add_option("--port", options.websocket.port, "TCP port to listen on (0: any free one)")
      ->capture_default_str();
  app.add_option("--max-clients", options.websocket.max_clients,
                 "connections served at once; more are refused (HTTP 503)")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{1024}));
  app.add_option("--topics", topics,
                 "serve only topics whose whole name matches this regular expression (ECMAScript)");
  app.add_option("--status-file", options.status_path,
                 "status file for agnocast-cli daemon status; its lock beside it allows one "
                 "server per file")
      ->capture_default_str();
  app.set_version_flag("--version", std::string(agnocast::library_version_string));
  agnocast_service::set_up_logging("agnocast-foxglove", "info",
                                   agnocast_service::stderr_is_journal(),
                                   agnocast_service::LogStyle::tagged);
  try {
    app.parse(argc, argv);
    if (!topics.empty()) options.topics.emplace(topics, std::regex::ECMAScript);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 2;
  } catch (const std::regex_error& error) {
    spdlog::error("--topics '{}' is not a regular expression: {}", topics, error.what());
    return 2;
  }
  try {
    return agnocast::foxglove::serve(options);
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
    return 1;
  }
}
