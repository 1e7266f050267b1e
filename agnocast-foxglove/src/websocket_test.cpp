// The WebSocket thread against a client written here on a plain socket: the
// handshake, frames both ways, work posted and a stop from other threads
// (what the ThreadSanitizer build checks), and the limits. Every wait is
// bounded, so a hang fails the test instead of stalling the suite.
#include "websocket.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace agnocast::foxglove {
namespace {

using namespace std::chrono_literals;

constexpr auto bound = 10s;

// What the handler saw, in order, as "opened 1", "text 1 hello", ...; the
// WebSocket thread writes it, the test's thread waits on it.
class Recorder : public WebSocketHandler {
 public:
  WebSocketServer* server = nullptr;

  void opened(ClientId client, const std::string&) override {
    add("opened " + std::to_string(client));
  }
  void closed(ClientId client) override { add("closed " + std::to_string(client)); }
  void text(ClientId client, const std::string& payload) override {
    add("text " + std::to_string(client) + " " + payload);
    server->send_text(client, "echo " + payload);
  }
  void binary(ClientId client, const std::string& payload) override {
    add("binary " + std::to_string(client) + " " + std::to_string(payload.size()));
  }
  void refused(const std::string&) override { add("refused"); }
  void tick() override {
    const std::lock_guard lock(mutex_);
    ++ticks_;
    changed_.notify_all();
  }

  // Waits until `event` was seen; false after `bound`.
  bool wait_for(const std::string& event) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, bound, [&] {
      for (const auto& seen : events_) {
        if (seen == event) return true;
      }
      return false;
    });
  }
  bool wait_for_ticks(int count) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, bound, [&] { return ticks_ >= count; });
  }
  std::vector<std::string> events() {
    const std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  void add(std::string event) {
    const std::lock_guard lock(mutex_);
    events_.push_back(std::move(event));
    changed_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::string> events_;
  int ticks_ = 0;
};

// A server on a port of the system's choosing, run on a thread of its own.
class Served {
 public:
  explicit Served(WebSocketOptions options) {
    options.port = 0;
    if (options.subprotocol.empty()) options.subprotocol = "test.v1";
    if (options.http_body.empty()) options.http_body = "a test server\n";
    server_.emplace(options, recorder);
    recorder.server = &*server_;
    thread_ = std::thread([this] {
      server_->run();
      const std::lock_guard lock(mutex_);
      ran_ = true;
      ended_.notify_all();
    });
  }
  ~Served() {
    server_->stop();
    thread_.join();
  }

  WebSocketServer& server() { return *server_; }
  std::uint16_t port() const { return server_->port(); }
  // Stops it from this thread; true when run() returned within the bound.
  bool stop() {
    server_->stop();
    std::unique_lock lock(mutex_);
    return ended_.wait_for(lock, bound, [&] { return ran_; });
  }

  Recorder recorder;

 private:
  std::optional<WebSocketServer> server_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable ended_;
  bool ran_ = false;
};

// A WebSocket client on a blocking socket, every read bounded.
class Client {
 public:
  explicit Client(std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error("socket: " + std::string(std::strerror(errno)));
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
      throw std::runtime_error("connect: " + std::string(std::strerror(errno)));
    }
  }
  ~Client() { ::close(fd_); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  // Sends an HTTP request and returns the response's head (status line and headers).
  std::string request(const std::string& head) {
    write_all(head);
    std::string response;
    while (response.find("\r\n\r\n") == std::string::npos) {
      const auto byte = read_bytes(1);
      if (!byte) break;
      response += *byte;
    }
    return response;
  }
  std::string upgrade(const std::string& subprotocol) {
    std::string head =
        "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n";
    if (!subprotocol.empty()) head += "Sec-WebSocket-Protocol: " + subprotocol + "\r\n";
    return request(head + "\r\n");
  }

  // One masked frame of `opcode` (1 text, 2 binary), as a client must send.
  void send_frame(int opcode, const std::string& payload) {
    std::string frame(1, static_cast<char>(0x80 | opcode));
    const std::size_t size = payload.size();
    if (size < 126) {
      frame += static_cast<char>(0x80 | size);
    } else if (size < 65536) {
      frame += static_cast<char>(0x80 | 126);
      for (int shift = 8; shift >= 0; shift -= 8) frame += static_cast<char>(size >> shift);
    } else {
      frame += static_cast<char>(0x80 | 127);
      for (int shift = 56; shift >= 0; shift -= 8) frame += static_cast<char>(size >> shift);
    }
    const char mask[4] = {0x12, 0x34, 0x56, 0x78};
    frame.append(mask, 4);
    for (std::size_t i = 0; i < size; ++i) frame += static_cast<char>(payload[i] ^ mask[i % 4]);
    write_all(frame);
  }

  struct Frame {
    int opcode;
    std::string payload;
  };
  // The next frame from the server; nullopt when the connection ended or
  // nothing came within the bound.
  std::optional<Frame> receive_frame() {
    const auto head = read_bytes(2);
    if (!head) return std::nullopt;
    const auto first = static_cast<unsigned char>((*head)[0]);
    std::uint64_t size = static_cast<unsigned char>((*head)[1]) & 0x7f;
    if (size >= 126) {
      const auto extended = read_bytes(size == 126 ? 2 : 8);
      if (!extended) return std::nullopt;
      size = 0;
      for (const char byte : *extended) size = (size << 8) | static_cast<unsigned char>(byte);
    }
    const auto payload = read_bytes(size);
    if (!payload) return std::nullopt;
    return Frame{first & 0x0f, *payload};
  }

 private:
  void write_all(const std::string& bytes) {
    std::size_t written = 0;
    while (written < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + written, bytes.size() - written, MSG_NOSIGNAL);
      if (n <= 0) throw std::runtime_error("send: " + std::string(std::strerror(errno)));
      written += static_cast<std::size_t>(n);
    }
  }
  std::optional<std::string> read_bytes(std::size_t count) {
    std::string bytes;
    const auto deadline = std::chrono::steady_clock::now() + bound;
    while (bytes.size() < count) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      pollfd readable{fd_, POLLIN, 0};
      if (left.count() <= 0 || ::poll(&readable, 1, static_cast<int>(left.count())) <= 0) {
        return std::nullopt;
      }
      char buffer[4096];
      const ssize_t n = ::recv(fd_, buffer, std::min(sizeof buffer, count - bytes.size()), 0);
      if (n <= 0) return std::nullopt;
      bytes.append(buffer, static_cast<std::size_t>(n));
    }
    return bytes;
  }

  int fd_ = -1;
};

// The status code of a close frame; 0 for another frame or one too short to carry it.
int close_code(const Client::Frame& frame) {
  if (frame.opcode != 8 || frame.payload.size() < 2) return 0;
  return (static_cast<unsigned char>(frame.payload[0]) << 8) |
         static_cast<unsigned char>(frame.payload[1]);
}

TEST(WebSocket, FramesGoBothWaysAndWorkPostedFromAnotherThreadRunsOnTheServersThread) {
  Served served({});
  Client client(served.port());
  ASSERT_NE(client.upgrade("test.v1").find("101"), std::string::npos);
  ASSERT_TRUE(served.recorder.wait_for("opened 1"));

  client.send_frame(1, "hello");
  ASSERT_TRUE(served.recorder.wait_for("text 1 hello"));
  auto reply = client.receive_frame();
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->opcode, 1);
  EXPECT_EQ(reply->payload, "echo hello");

  // A payload past the 16-bit length, and one the server sends when posted.
  client.send_frame(2, std::string(70'000, 'x'));
  ASSERT_TRUE(served.recorder.wait_for("binary 1 70000"));
  std::thread poster(
      [&] { served.server().post([&] { served.server().send_binary(1, "\x01\x02\x03", 3); }); });
  poster.join();
  reply = client.receive_frame();
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->opcode, 2);
  EXPECT_EQ(reply->payload, "\x01\x02\x03");
  EXPECT_TRUE(served.recorder.wait_for_ticks(2));
}

TEST(WebSocket, StopFromAnotherThreadClosesClientsAsGoingAwayAndEndsRun) {
  Served served({});
  Client first(served.port()), second(served.port());
  ASSERT_NE(first.upgrade("test.v1").find("101"), std::string::npos);
  ASSERT_NE(second.upgrade("test.v1").find("101"), std::string::npos);
  ASSERT_TRUE(served.recorder.wait_for("opened 2"));

  ASSERT_TRUE(served.stop());
  for (Client* client : {&first, &second}) {
    const auto close = client->receive_frame();
    ASSERT_TRUE(close);
    EXPECT_EQ(close_code(*close), 1001);
  }
}

TEST(WebSocket, AClientWithoutTheSubprotocolIsRefusedAndAPlainRequestGetsTheBody) {
  Served served({});
  {
    Client client(served.port());
    const std::string response = client.upgrade("other.v1");
    EXPECT_NE(response.find("400"), std::string::npos) << response;
  }
  {
    Client client(served.port());
    EXPECT_NE(client.upgrade("").find("400"), std::string::npos);
  }
  Client browser(served.port());
  const std::string response =
      browser.request("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  EXPECT_NE(response.find("200"), std::string::npos) << response;
  for (const auto& event : served.recorder.events())
    EXPECT_EQ(event.rfind("opened", 0), std::string::npos);
}

TEST(WebSocket, AClientBeyondMaxClientsIsRefusedWhileTheOthersStay) {
  WebSocketOptions options;
  options.max_clients = 1;
  Served served(options);
  Client first(served.port());
  ASSERT_NE(first.upgrade("test.v1").find("101"), std::string::npos);
  ASSERT_TRUE(served.recorder.wait_for("opened 1"));
  Client second(served.port());
  EXPECT_NE(second.upgrade("test.v1").find("503"), std::string::npos);
  EXPECT_TRUE(served.recorder.wait_for("refused"));

  first.send_frame(1, "still here");
  const auto reply = first.receive_frame();
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->payload, "echo still here");
}

TEST(WebSocket, AFrameBeyondTheLimitClosesItsConnectionAsTooBig) {
  WebSocketOptions options;
  options.max_incoming_bytes = 1000;
  Served served(options);
  Client client(served.port());
  ASSERT_NE(client.upgrade("test.v1").find("101"), std::string::npos);
  client.send_frame(2, std::string(1001, 'x'));
  const auto close = client.receive_frame();
  ASSERT_TRUE(close);
  EXPECT_EQ(close_code(*close), 1009);
  client.send_frame(8, close->payload);  // the close handshake's answer
  EXPECT_TRUE(served.recorder.wait_for("closed 1"));
  for (const auto& event : served.recorder.events())
    EXPECT_EQ(event.rfind("binary", 0), std::string::npos);
}

TEST(WebSocket, AnAddressThatIsNotIpOrAPortInUseThrowsNamingIt) {
  Recorder recorder;
  WebSocketOptions options;
  options.address = "localhost";
  options.port = 0;
  try {
    WebSocketServer server(options, recorder);
    FAIL() << "a host name was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("'localhost' is not an IP address"),
              std::string::npos);
  }
  Served served({});
  options.address = "127.0.0.1";
  options.port = served.port();
  try {
    WebSocketServer server(options, recorder);
    FAIL() << "a port in use was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what())
                  .find("cannot listen on 127.0.0.1 port " + std::to_string(options.port)),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace agnocast::foxglove
