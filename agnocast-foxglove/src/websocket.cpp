// Built as C++17 (websocket.hpp says why).
#define ASIO_STANDALONE
#include "websocket.hpp"

#include <map>
#include <stdexcept>
#include <utility>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace agnocast::foxglove {

using Endpoint = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;

class WebSocketServer::Impl {
 public:
  Impl(const WebSocketOptions& options, WebSocketHandler& handler)
      : options_(options), handler_(handler), timer_(io_) {
    // Our own log lines say what matters; websocketpp's would repeat them.
    endpoint_.clear_access_channels(websocketpp::log::alevel::all);
    endpoint_.clear_error_channels(websocketpp::log::elevel::all);
    endpoint_.init_asio(&io_);
    endpoint_.set_reuse_addr(true);
    endpoint_.set_max_message_size(options.max_incoming_bytes);
    endpoint_.set_validate_handler([this](Handle handle) { return validate(handle); });
    endpoint_.set_http_handler([this](Handle handle) {
      const auto connection = endpoint_.get_con_from_hdl(handle);
      connection->set_status(websocketpp::http::status_code::ok);
      connection->replace_header("Content-Type", "text/plain; charset=utf-8");
      connection->set_body(options_.http_body);
    });
    endpoint_.set_open_handler([this](Handle handle) {
      const ClientId id = next_id_++;
      clients_.emplace(id, handle);
      ids_.emplace(handle, id);
      handler_.opened(id, remote(handle));
    });
    endpoint_.set_close_handler([this](Handle handle) { forget(handle); });
    endpoint_.set_fail_handler([this](Handle handle) { forget(handle); });
    endpoint_.set_message_handler([this](Handle handle, Endpoint::message_ptr message) {
      const auto found = ids_.find(handle);
      if (found == ids_.end()) return;
      if (message->get_opcode() == websocketpp::frame::opcode::text) {
        handler_.text(found->second, message->get_payload());
      } else {
        handler_.binary(found->second, message->get_payload());
      }
    });

    asio::error_code error;
    const asio::ip::address address = asio::ip::make_address(options.address, error);
    if (error) throw std::runtime_error("'" + options.address + "' is not an IP address");
    endpoint_.listen(asio::ip::tcp::endpoint(address, options.port), error);
    if (error) {
      throw std::runtime_error("cannot listen on " + options.address + " port " +
                               std::to_string(options.port) + ": " + error.message());
    }
    endpoint_.start_accept(error);
    if (error) throw std::runtime_error("cannot accept connections: " + error.message());
    port_ = endpoint_.get_local_endpoint(error).port();
  }

  std::uint16_t port() const { return port_; }

  void run() {
    arm_timer();
    io_.run();
  }

  void stop() {
    asio::post(io_, [this] {
      stopping_ = true;
      asio::error_code ignored;
      endpoint_.stop_listening(ignored);
      timer_.cancel();
      for (const auto& [id, handle] : clients_) {
        endpoint_.close(handle, websocketpp::close::status::going_away, "server stopping", ignored);
      }
      // Clients that do not answer the close handshake are not waited for long.
      auto deadline = std::make_shared<asio::steady_timer>(io_, std::chrono::seconds(1));
      deadline->async_wait([this, deadline](const asio::error_code&) { io_.stop(); });
      if (clients_.empty()) io_.stop();
    });
  }

  void post(std::function<void()> work) { asio::post(io_, std::move(work)); }

  void send(ClientId client, const void* data, std::size_t size,
            websocketpp::frame::opcode::value opcode) {
    const auto found = clients_.find(client);
    if (found == clients_.end()) return;
    asio::error_code ignored;  // a connection that is closing: its close handler follows
    endpoint_.send(found->second, data, size, opcode, ignored);
  }

  std::size_t buffered_bytes(ClientId client) {
    const auto found = clients_.find(client);
    if (found == clients_.end()) return 0;
    asio::error_code error;
    const auto connection = endpoint_.get_con_from_hdl(found->second, error);
    return error ? 0 : connection->get_buffered_amount();
  }

  void close(ClientId client, std::uint16_t code, const std::string& reason) {
    const auto found = clients_.find(client);
    if (found == clients_.end()) return;
    asio::error_code ignored;
    endpoint_.close(found->second, code, reason, ignored);
  }

 private:
  bool validate(Handle handle) {
    const auto connection = endpoint_.get_con_from_hdl(handle);
    if (stopping_) return false;
    if (clients_.size() >= options_.max_clients) {
      connection->set_status(websocketpp::http::status_code::service_unavailable,
                             "too many clients");
      handler_.refused(remote(handle));
      return false;
    }
    for (const std::string& requested : connection->get_requested_subprotocols()) {
      if (requested == options_.subprotocol) {
        connection->select_subprotocol(requested);
        return true;
      }
    }
    connection->set_status(websocketpp::http::status_code::bad_request,
                           "subprotocol " + options_.subprotocol + " required");
    return false;
  }

  std::string remote(Handle handle) {
    asio::error_code error;
    const auto connection = endpoint_.get_con_from_hdl(handle, error);
    return error ? std::string("?") : connection->get_remote_endpoint();
  }

  void forget(Handle handle) {
    const auto found = ids_.find(handle);
    if (found == ids_.end()) return;
    const ClientId id = found->second;
    ids_.erase(found);
    clients_.erase(id);
    handler_.closed(id);
    if (stopping_ && clients_.empty()) io_.stop();
  }

  void arm_timer() {
    timer_.expires_after(std::chrono::milliseconds(tick_ms));
    timer_.async_wait([this](const asio::error_code& error) {
      if (error || stopping_) return;
      handler_.tick();
      arm_timer();
    });
  }

  WebSocketOptions options_;
  WebSocketHandler& handler_;
  asio::io_context io_;
  asio::steady_timer timer_;
  Endpoint endpoint_;
  std::uint16_t port_ = 0;
  bool stopping_ = false;
  ClientId next_id_ = 1;
  std::map<ClientId, Handle> clients_;
  std::map<Handle, ClientId, std::owner_less<Handle>> ids_;
};

WebSocketServer::WebSocketServer(const WebSocketOptions& options, WebSocketHandler& handler)
    : impl_(std::make_unique<Impl>(options, handler)) {}
WebSocketServer::~WebSocketServer() = default;
std::uint16_t WebSocketServer::port() const { return impl_->port(); }
void WebSocketServer::run() { impl_->run(); }
void WebSocketServer::stop() { impl_->stop(); }
void WebSocketServer::post(std::function<void()> work) { impl_->post(std::move(work)); }
void WebSocketServer::send_text(ClientId client, const std::string& payload) {
  impl_->send(client, payload.data(), payload.size(), websocketpp::frame::opcode::text);
}
void WebSocketServer::send_binary(ClientId client, const void* data, std::size_t size) {
  impl_->send(client, data, size, websocketpp::frame::opcode::binary);
}
std::size_t WebSocketServer::buffered_bytes(ClientId client) const {
  return impl_->buffered_bytes(client);
}
void WebSocketServer::close(ClientId client, std::uint16_t code, const std::string& reason) {
  impl_->close(client, code, reason);
}

}  // namespace agnocast::foxglove
