// agnocast-foxglove's server: every typed agnocast topic as a foxglove.websocket.v1
// channel, live.
//
// Two threads. The WebSocket thread (websocket.hpp) reads clients' frames,
// answers malformed ones at once and hands the rest to the agnocast thread,
// which owns the node: it finds topics, subscribes and publishes for clients,
// and puts what a client is to receive into that client's Outbox.
//
// Never slowing a publisher: each client subscription is a kernel subscriber
// of its own (node agnocast_foxglove). A received message is turned into CDR
// and released inside the callback, so the server holds no entry beyond it.
// A client whose outbox is full (its socket does not take the bytes) is not
// read for: its subscribers' messages stay with the kernel, which drops the
// oldest beyond the subscriber's depth and counts them, per client, in
// `agnocast-cli topic info`. Memory per client is bounded by the outbox and
// what websocketpp buffers for the socket.
#pragma once

#include <cstdint>
#include <optional>
#include <regex>
#include <string>

#include "websocket.hpp"

namespace agnocast::foxglove {

struct ServerOptions {
  WebSocketOptions websocket;
  std::optional<std::regex> topics;  // only topics whose whole name matches
  // Its status file (agnocast-cli daemon status), its lock beside it: one
  // server per status file.
  std::string status_path;
};

// Serves until SIGINT/SIGTERM/SIGHUP. Throws agnocast_service::AlreadyRunning
// when another server writes the status file, std::runtime_error when it
// cannot listen, agnocast::Error when the module is not there.
int serve(const ServerOptions& options);

}  // namespace agnocast::foxglove
