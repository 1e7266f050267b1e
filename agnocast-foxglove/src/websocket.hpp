// The WebSocket side of agnocast-foxglove: websocketpp over standalone Asio,
// every connection served by one thread. websocketpp 0.8 does not compile as
// C++20, so websocket.cpp is built as C++17 and this header, which both sides
// include, holds nothing websocketpp's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace agnocast::foxglove {

using ClientId = std::uint64_t;

struct WebSocketOptions {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8765;
  std::size_t max_clients = 16;
  // A client's frame beyond this closes its connection (1009, message too big).
  std::size_t max_incoming_bytes = 8 << 20;
  // The subprotocol a client must ask for; others are refused in the handshake.
  std::string subprotocol;
  // What a plain HTTP request (a browser opening the address) is told.
  std::string http_body;
};

// Called on the WebSocket thread.
class WebSocketHandler {
 public:
  virtual ~WebSocketHandler() = default;
  virtual void opened(ClientId client, const std::string& remote) = 0;
  virtual void closed(ClientId client) = 0;
  virtual void text(ClientId client, const std::string& payload) = 0;
  virtual void binary(ClientId client, const std::string& payload) = 0;
  // A connection refused because --max-clients are connected.
  virtual void refused(const std::string& remote) = 0;
  // Every tick_ms while the server runs.
  virtual void tick() = 0;
};

class WebSocketServer {
 public:
  static constexpr int tick_ms = 50;

  // Listens at once; throws std::runtime_error naming the address when it cannot.
  WebSocketServer(const WebSocketOptions& options, WebSocketHandler& handler);
  ~WebSocketServer();
  WebSocketServer(const WebSocketServer&) = delete;
  WebSocketServer& operator=(const WebSocketServer&) = delete;

  // The port listened on (the one the system chose for port 0).
  std::uint16_t port() const;
  // Serves until stop(); call from the thread that is to be the WebSocket thread.
  void run();
  // From any thread: stops listening, closes every connection, ends run().
  void stop();
  // From any thread: runs `work` on the WebSocket thread.
  void post(std::function<void()> work);

  // On the WebSocket thread only. Sending to a client that has gone does nothing.
  void send_text(ClientId client, const std::string& payload);
  void send_binary(ClientId client, const void* data, std::size_t size);
  // Bytes handed to the connection and not yet written to its socket.
  std::size_t buffered_bytes(ClientId client) const;
  void close(ClientId client, std::uint16_t code, const std::string& reason);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace agnocast::foxglove
