#include "server.hpp"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "agnocast/errors.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/node.hpp"
#include "agnocast/schema_cdr.hpp"
#include "agnocast/schema_definition.hpp"
#include "agnocast/schema_publisher.hpp"
#include "agnocast/schema_subscription.hpp"
#include "agnocast/schema_topic.hpp"
#include "agnocast/topic_watcher.hpp"
#include "agnocast_service/service_loop.hpp"
#include "agnocast_service/timer.hpp"
#include "protocol.hpp"

namespace agnocast::foxglove {
namespace {

// A client's outbox holds at most this many messages and bytes; websocketpp
// is handed more only while less than socket_watermark waits for the socket.
constexpr std::size_t outbox_messages = 64;
constexpr std::size_t outbox_bytes = 16 << 20;
constexpr std::size_t socket_watermark = 4 << 20;
// Deep enough for bursts; beyond it the kernel drops the oldest for that client only.
constexpr std::size_t subscription_depth = 16;
constexpr std::size_t publisher_depth = 10;
// clientPublish bytes waiting for the agnocast thread, per server: more are refused.
constexpr std::size_t pending_publish_bytes = 32 << 20;
// Status messages waiting for one client: a client that sends bad requests
// and reads nothing gets no more.
constexpr std::size_t outbox_statuses = 256;
constexpr auto discovery_interval = std::chrono::seconds(1);
constexpr int time_every_ticks = 2;  // a time frame every 100 ms

std::uint64_t realtime_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// What one client is to receive, in order; filled by the agnocast thread,
// emptied into the socket by the WebSocket thread.
struct Outbox {
  struct Frame {
    bool text = false;
    bool data = false;  // a message (counts against the bounds); else a control frame
    bool status = false;
    std::string bytes;
  };
  std::mutex mutex;
  std::deque<Frame> frames;
  std::size_t data_frames = 0;
  std::size_t data_bytes = 0;
  std::size_t statuses = 0;
  bool flush_posted = false;

  bool full() const { return data_frames >= outbox_messages || data_bytes >= outbox_bytes; }
};

struct Open {
  ClientId client;
  std::shared_ptr<Outbox> outbox;
};
struct Close {
  ClientId client;
};
struct Request {
  ClientId client;
  ClientRequest request;
};
struct Publish {
  ClientId client;
  std::uint32_t channel_id;
  std::vector<std::uint8_t> cdr;
};
using Command = std::variant<Open, Close, Request, Publish>;

// One client subscription: its own kernel subscriber.
struct Subscription {
  std::uint32_t channel_id = 0;
  std::unique_ptr<SchemaSubscription> kernel;
  std::vector<std::uint8_t> cdr;  // reused for every message
};

struct Client {
  std::shared_ptr<Outbox> outbox;
  std::map<std::uint32_t, std::unique_ptr<Subscription>> subscriptions;  // by subscription id
  std::map<std::uint32_t, std::unique_ptr<SchemaPublisher>> publishers;  // by client channel id
  bool behind = false;  // its outbox was full when last looked at
};

struct KnownChannel {
  Channel channel;
  std::string type_name;
  std::uint64_t type_hash = 0;
};

class Server final : public WebSocketHandler {
 public:
  Server(const ServerOptions& options, agnocast_service::ServiceLoop& service)
      : options_(options),
        service_(service),
        wake_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)),
        node_("agnocast_foxglove"),
        websocket_(options.websocket, *this) {
    if (wake_fd_ < 0) throw std::runtime_error("eventfd failed");
  }
  ~Server() override { ::close(wake_fd_); }

  int run() {
    discover();  // the module's absence is an error before anyone connects
    const std::string& address = options_.websocket.address;
    const std::string host = address.find(':') == std::string::npos ? address : "[" + address + "]";
    const std::string serving = "serving " + std::string(subprotocol) + " on ws://" + host + ":" +
                                std::to_string(websocket_.port());
    spdlog::info("{}", serving);
    agnocast_service::PeriodicTimer discovery_timer(discovery_interval);
    service_.add_fd(discovery_timer.fd(), "the discovery timer", [this, &discovery_timer] {
      discovery_timer.consume();
      discover();
    });
    std::thread websocket_thread([this] {
      websocket_.run();
      websocket_running_ = false;
    });
    agnocast_service::ServiceHooks hooks;
    hooks.status_body = [this](const agnocast::ServiceStatus&) { return status_body(); };
    // The watchdog is pinged from this loop, and only while the WebSocket
    // thread's loop runs too.
    hooks.healthy = [this] {
      if (!websocket_running_)
        spdlog::error("the WebSocket thread stopped; not pinging the watchdog");
      return websocket_running_.load();
    };
    try {
      service_.ready(serving, std::move(hooks));
      while (!service_.stopping()) {
        handle_commands();
        wait_and_receive();
      }
    } catch (...) {
      websocket_.stop();
      websocket_thread.join();
      throw;
    }
    websocket_.stop();
    websocket_thread.join();
    service_.remove_fd(discovery_timer.fd());
    clients_.clear();
    service_.stopped();
    return 0;
  }

  // ---- The WebSocket thread ----

  void opened(ClientId client, const std::string& remote) override {
    auto outbox = std::make_shared<Outbox>();
    outboxes_[client] = outbox;
    spdlog::info("client {} connected from {}", client, remote);
    push(Open{client, std::move(outbox)});
  }

  void closed(ClientId client) override {
    outboxes_.erase(client);
    spdlog::info("client {} disconnected", client);
    push(Close{client});
  }

  void refused(const std::string& remote) override {
    spdlog::warn("refused a client from {}: {} are connected (--max-clients)", remote,
                 options_.websocket.max_clients);
  }

  void text(ClientId client, const std::string& payload) override {
    try {
      push(Request{client, parse_client_request(payload)});
    } catch (const ProtocolError& error) {
      reply(client, StatusLevel::Error, error.what());
    }
  }

  void binary(ClientId client, const std::string& payload) override {
    try {
      const ClientMessage message = parse_client_message(payload);
      if (publish_bytes_waiting_ + message.payload.size() > pending_publish_bytes) {
        reply(client, StatusLevel::Warning, "server busy: a clientPublish message was dropped");
        return;
      }
      publish_bytes_waiting_ += message.payload.size();
      push(Publish{client, message.channel_id, {message.payload.begin(), message.payload.end()}});
    } catch (const ProtocolError& error) {
      reply(client, StatusLevel::Error, error.what());
    }
  }

  void tick() override {
    const bool send_time = ++ticks_ % time_every_ticks == 0;
    const std::string time = send_time ? time_frame(realtime_ns()) : std::string();
    for (const auto& [client, outbox] : outboxes_) {
      flush(client, *outbox);
      if (send_time && websocket_.buffered_bytes(client) < socket_watermark) {
        websocket_.send_binary(client, time.data(), time.size());
      }
    }
  }

 private:
  // Hands the outbox's frames to websocketpp while the socket keeps up.
  void flush(ClientId client, Outbox& outbox) {
    bool made_room = false;
    {
      const std::lock_guard lock(outbox.mutex);
      outbox.flush_posted = false;
      const bool was_full = outbox.full();
      while (!outbox.frames.empty() && websocket_.buffered_bytes(client) < socket_watermark) {
        Outbox::Frame& frame = outbox.frames.front();
        if (frame.text) {
          websocket_.send_text(client, frame.bytes);
        } else {
          websocket_.send_binary(client, frame.bytes.data(), frame.bytes.size());
        }
        if (frame.data) {
          --outbox.data_frames;
          outbox.data_bytes -= frame.bytes.size();
        }
        if (frame.status) --outbox.statuses;
        outbox.frames.pop_front();
      }
      made_room = was_full && !outbox.full();
    }
    if (made_room) wake();  // the agnocast thread reads for this client again
  }

  // A status straight from the WebSocket thread, unless the client reads too slowly to take it.
  void reply(ClientId client, StatusLevel level, const std::string& message) {
    if (websocket_.buffered_bytes(client) < socket_watermark) {
      websocket_.send_text(client, status_json(level, message));
    }
  }

  void push(Command command) {
    {
      const std::lock_guard lock(commands_mutex_);
      commands_.push_back(std::move(command));
    }
    wake();
  }

  void wake() {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t written = ::write(wake_fd_, &one, sizeof one);
  }

  // ---- The agnocast thread ----

  void send(ClientId client, Client& state, std::string text) {
    {
      const std::lock_guard lock(state.outbox->mutex);
      state.outbox->frames.push_back(
          {.text = true, .data = false, .status = false, .bytes = std::move(text)});
    }
    post_flush(client, state.outbox);
  }

  void status(ClientId client, Client& state, StatusLevel level, const std::string& message) {
    {
      const std::lock_guard lock(state.outbox->mutex);
      if (state.outbox->statuses >= outbox_statuses) return;
      ++state.outbox->statuses;
      state.outbox->frames.push_back(
          {.text = true, .data = false, .status = true, .bytes = status_json(level, message)});
    }
    post_flush(client, state.outbox);
  }

  void post_flush(ClientId client, const std::shared_ptr<Outbox>& outbox) {
    {
      const std::lock_guard lock(outbox->mutex);
      if (outbox->flush_posted) return;
      outbox->flush_posted = true;
    }
    websocket_.post([this, client, outbox] {
      if (outboxes_.contains(client)) flush(client, *outbox);
    });
  }

  void handle_commands() {
    std::vector<Command> commands;
    {
      const std::lock_guard lock(commands_mutex_);
      commands.swap(commands_);
    }
    for (Command& command : commands) {
      std::visit([this](auto& c) { handle(c); }, command);
    }
  }

  void handle(Open& open) {
    Client& client = clients_[open.client];
    client.outbox = std::move(open.outbox);
    send(open.client, client, server_info_json("agnocast-foxglove", session_id_));
    std::vector<Channel> channels;
    for (const auto& [topic, known] : channels_) channels.push_back(known.channel);
    send(open.client, client, advertise_json(channels));
  }

  void handle(Close& close) {
    const auto found = clients_.find(close.client);
    if (found == clients_.end()) return;
    for (const auto& [id, subscription] : found->second.subscriptions)
      forget_endpoint(*subscription);
    for (const auto& [id, publisher] : found->second.publishers) --ours_[publisher->topic()];
    clients_.erase(found);
  }

  void handle(Request& request) {
    const auto found = clients_.find(request.client);
    if (found == clients_.end()) return;
    std::visit([&](auto& r) { handle(request.client, found->second, r); }, request.request);
  }

  void handle(Publish& publish) {
    publish_bytes_waiting_ -= publish.cdr.size();
    const auto found = clients_.find(publish.client);
    if (found == clients_.end()) return;
    Client& client = found->second;
    const auto publisher = client.publishers.find(publish.channel_id);
    if (publisher == client.publishers.end()) {
      status(publish.client, client, StatusLevel::Error,
             "message for channel " + std::to_string(publish.channel_id) +
                 ", which this client has not advertised");
      return;
    }
    try {
      publisher->second->publish_cdr(publish.cdr);
    } catch (const std::exception& error) {
      status(publish.client, client, StatusLevel::Error,
             "cannot publish on " + publisher->second->topic() + ": " + error.what());
    }
  }

  void handle(ClientId id, Client& client, Subscribe& request) {
    for (const Subscribe::Item& item : request.subscriptions) {
      if (client.subscriptions.contains(item.id)) {
        status(id, client, StatusLevel::Error,
               "subscription id " + std::to_string(item.id) + " is already in use");
        continue;
      }
      const auto topic = channel_topics_.find(item.channel_id);
      if (topic == channel_topics_.end()) {
        status(id, client, StatusLevel::Error,
               "unknown channel " + std::to_string(item.channel_id));
        continue;
      }
      bool duplicate = false;
      for (const auto& [sub_id, subscription] : client.subscriptions) {
        duplicate = duplicate || subscription->channel_id == item.channel_id;
      }
      if (duplicate) {
        status(id, client, StatusLevel::Error,
               "channel " + std::to_string(item.channel_id) + " is already subscribed");
        continue;
      }
      try {
        client.subscriptions[item.id] =
            subscribe(id, client, item.id, item.channel_id, topic->second);
      } catch (const std::exception& error) {
        status(id, client, StatusLevel::Error,
               "cannot subscribe to " + topic->second + ": " + error.what());
      }
    }
  }

  void handle(ClientId id, Client& client, Unsubscribe& request) {
    for (const std::uint32_t sub_id : request.subscription_ids) {
      const auto found = client.subscriptions.find(sub_id);
      if (found == client.subscriptions.end()) {
        status(id, client, StatusLevel::Warning,
               "no subscription " + std::to_string(sub_id) + " to end");
        continue;
      }
      forget_endpoint(*found->second);
      client.subscriptions.erase(found);
    }
  }

  void handle(ClientId id, Client& client, ClientAdvertise& request) {
    for (const ClientAdvertise::Item& item : request.channels) {
      try {
        if (client.publishers.contains(item.id)) {
          throw ProtocolError("client channel " + std::to_string(item.id) +
                              " is already advertised");
        }
        if (item.encoding != "cdr") {
          throw ProtocolError("encoding '" + item.encoding + "' is not supported (only cdr)");
        }
        std::optional<SchemaTopic> live = find_schema_topic(item.topic);
        if (!live) {
          throw ProtocolError("topic " + item.topic +
                              " has no typed endpoint, so its layout is unknown: start a "
                              "subscriber of it first");
        }
        if (ros2msg_type_name(item.schema_name) != ros2msg_type_name(live->type_name)) {
          throw ProtocolError("topic " + item.topic + " has type " + live->type_name + ", not " +
                              item.schema_name);
        }
        client.publishers[item.id] = std::make_unique<SchemaPublisher>(
            node_, item.topic, QoS(publisher_depth), live->type_name, live->type_hash,
            std::move(live->blob));
        ++ours_[item.topic];
      } catch (const std::exception& error) {
        status(id, client, StatusLevel::Error,
               "cannot publish on " + item.topic + ": " + error.what());
      }
    }
  }

  void handle(ClientId id, Client& client, ClientUnadvertise& request) {
    for (const std::uint32_t channel_id : request.channel_ids) {
      const auto found = client.publishers.find(channel_id);
      if (found == client.publishers.end()) {
        status(id, client, StatusLevel::Warning,
               "no client channel " + std::to_string(channel_id) + " to unadvertise");
        continue;
      }
      --ours_[found->second->topic()];
      client.publishers.erase(found);
    }
  }

  std::unique_ptr<Subscription> subscribe(ClientId id, Client& client, std::uint32_t sub_id,
                                          std::uint32_t channel_id, const std::string& topic) {
    auto subscription = std::make_unique<Subscription>();
    subscription->channel_id = channel_id;
    Subscription* raw = subscription.get();
    std::shared_ptr<Outbox> outbox = client.outbox;
    subscription->kernel = std::make_unique<SchemaSubscription>(
        node_, topic, QoS(subscription_depth),
        [this, id, sub_id, raw, outbox](const SchemaMessage& message, const MessageInfo& info) {
          // The publisher stamped its steady clock; clients get the epoch (as time frames).
          const std::uint64_t now = realtime_ns();
          const std::int64_t age = steady_ns() - info.publish_time;
          const std::uint64_t stamp =
              info.publish_time > 0 && age >= 0 ? now - static_cast<std::uint64_t>(age) : now;
          try {
            serialize_with_schema(message.data(), raw->kernel->schema(), raw->cdr,
                                  {.readable = message.readable()});
          } catch (const std::exception& error) {
            spdlog::warn("a message on {} has no CDR form: {}", raw->kernel->topic(), error.what());
            return;
          }
          std::string frame = message_data_frame(sub_id, stamp, raw->cdr);
          {
            const std::lock_guard lock(outbox->mutex);
            ++outbox->data_frames;
            outbox->data_bytes += frame.size();
            outbox->frames.push_back(
                {.text = false, .data = true, .status = false, .bytes = std::move(frame)});
          }
          post_flush(id, outbox);
        });
    ++ours_[topic];
    return subscription;
  }

  void forget_endpoint(const Subscription& subscription) { --ours_[subscription.kernel->topic()]; }

  void wait_and_receive() {
    // The service's descriptor: signals, the watchdog, the status and discovery timers.
    std::vector<pollfd> fds{{wake_fd_, POLLIN, 0}, {service_.fd(), POLLIN, 0}};
    constexpr std::size_t first_subscription = 2;
    std::vector<Subscription*> polled;
    for (auto& [id, client] : clients_) {
      bool full = false;
      {
        const std::lock_guard lock(client.outbox->mutex);
        full = client.outbox->full();
      }
      if (full != client.behind) {
        client.behind = full;
        spdlog::info("client {}{}", id,
                     full ? " does not keep up: the kernel drops its oldest messages "
                            "(agnocast-cli topic info, node agnocast_foxglove)"
                          : " keeps up again");
      }
      if (full) continue;  // its messages wait in the kernel, which drops beyond the depth
      for (auto& [sub_id, subscription] : client.subscriptions) {
        fds.push_back({subscription->kernel->wait_fd(), POLLIN, 0});
        polled.push_back(subscription.get());
      }
    }
    if (::poll(fds.data(), fds.size(), -1) <= 0) return;
    if (fds[0].revents != 0) {
      std::uint64_t count = 0;
      [[maybe_unused]] const ssize_t read = ::read(wake_fd_, &count, sizeof count);
    }
    if (fds[1].revents != 0 && !service_.dispatch()) return;
    for (std::size_t i = first_subscription; i < fds.size(); ++i) {
      if (fds[i].revents != 0) polled[i - first_subscription]->kernel->receive();
    }
  }

  // The server's fields of its status file, after the head.
  nlohmann::json status_body() const {
    std::size_t subscriptions = 0;
    for (const auto& [id, client] : clients_) subscriptions += client.subscriptions.size();
    return {{"address", options_.websocket.address},
            {"port", websocket_.port()},
            {"clients", clients_.size()},
            {"channels", channels_.size()},
            {"subscriptions", subscriptions}};
  }

  // Which topics are channels: a typed topic while an endpoint that is not this
  // server's uses it, with bag record's definitions.
  TopicWatcherOptions watched_topics() {
    TopicWatcherOptions watched;
    if (options_.topics) {
      watched.wanted = [this](const std::string& name) {
        return std::regex_match(name, *options_.topics);
      };
    }
    watched.own_endpoints = [this](const std::string& name) {
      const auto ours = ours_.find(name);
      return ours == ours_.end() ? 0u : ours->second;
    };
    return watched;
  }

  // Topics appear, change type and disappear; clients hear of each change.
  void discover() {
    const TopicChanges changes = watcher_.poll();
    std::vector<std::uint32_t> removed;
    for (const std::string& name : changes.gone) {
      const auto known = channels_.find(name);
      if (known == channels_.end()) continue;
      const std::uint32_t id = known->second.channel.id;
      removed.push_back(id);
      channel_topics_.erase(id);
      for (auto& [client_id, client] : clients_) {
        std::erase_if(client.subscriptions, [&](const auto& entry) {
          if (entry.second->channel_id != id) return false;
          forget_endpoint(*entry.second);
          return true;
        });
      }
      channels_.erase(known);
    }
    std::vector<Channel> added;
    for (const WatchedTopic& found : changes.appeared) {
      const SchemaTopic& topic = found.topic;
      const std::string identity = topic.topic + "\n" + topic.type_name + "\n" + found.definition;
      auto id = channel_ids_.find(identity);
      if (id == channel_ids_.end()) id = channel_ids_.emplace(identity, next_channel_id_++).first;
      KnownChannel channel{{id->second, topic.topic, topic.type_name, found.definition},
                           topic.type_name,
                           topic.type_hash};
      channel_topics_[channel.channel.id] = topic.topic;
      added.push_back(channel.channel);
      channels_.insert_or_assign(topic.topic, std::move(channel));
    }
    for (const RefusedTopic& topic : changes.refused) {
      spdlog::warn("not serving {} ({}): {}", topic.name, topic.type_name, topic.problem);
    }
    for (auto& [client_id, client] : clients_) {
      if (!removed.empty()) send(client_id, client, unadvertise_json(removed));
      if (!added.empty()) send(client_id, client, advertise_json(added));
    }
    for (const Channel& channel : added)
      spdlog::info("advertising {} ({})", channel.topic, channel.schema_name);
  }

  const ServerOptions& options_;
  agnocast_service::ServiceLoop& service_;
  const int wake_fd_;
  const std::string session_id_ = std::to_string(realtime_ns());
  Node node_;
  WebSocketServer websocket_;

  // The agnocast thread's.
  std::map<ClientId, Client> clients_;
  std::map<std::string, KnownChannel> channels_;         // by topic
  std::map<std::uint32_t, std::string> channel_topics_;  // channel id -> topic
  std::map<std::string, std::uint32_t> channel_ids_;     // topic, type and schema -> id, kept
  std::uint32_t next_channel_id_ = 1;
  std::map<std::string, std::uint32_t> ours_;  // this server's endpoints per topic
  TopicWatcher watcher_{watched_topics()};

  // The WebSocket thread's.
  std::map<ClientId, std::shared_ptr<Outbox>> outboxes_;
  unsigned ticks_ = 0;

  // Shared.
  std::mutex commands_mutex_;
  std::vector<Command> commands_;
  std::atomic<std::size_t> publish_bytes_waiting_ = 0;
  std::atomic<bool> websocket_running_ = true;
};

}  // namespace

int serve(const ServerOptions& options) {
  // One server per status file; the signals queue for the service's
  // descriptor from here on, in every thread started later. A user without
  // access to /run/agnocast runs it without the status file.
  agnocast_service::ServiceLoop service({.program = "agnocast-foxglove",
                                         .status_path = options.status_path,
                                         .status_optional = true});
  Server server(options, service);
  return server.run();
}

}  // namespace agnocast::foxglove
