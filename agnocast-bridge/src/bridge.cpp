#include "bridge.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/errors.hpp"
#include "agnocast/executor.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/status.hpp"
#include "agnocast/version.hpp"
#include "agnocast_service/journal_log.hpp"
#include "agnocast_service/notify.hpp"
#include "agnocast_service/service_loop.hpp"
#include "config.hpp"
#include "dds_domain.hpp"
#include "status_file.hpp"

namespace agnocast_bridge {
namespace {

constexpr const char* node_name = "agnocast_bridge";
constexpr int exit_failure = 1;
constexpr int exit_usage = 2;  // a bad command line or configuration

// How long the DDS receiver waits before it turns its loop again when no
// sample comes: it proves it is alive at least this often.
constexpr auto receiver_turn = std::chrono::seconds(1);

// Bridged topics and services whose type is not in the registry are configuration errors.
void check_types(const Config& config, const TypeRegistry& types) {
  // The standard set alone has over a hundred types: named by --list-types, not here.
  const std::string known = " (--list-types shows the " +
                            std::to_string(types.type_names().size()) + " message and " +
                            std::to_string(types.service_type_names().size()) +
                            " service types it knows; a bridge for other types is built with "
                            "agnocast_add_bridge())";
  for (std::size_t i = 0; i < config.topics.size(); ++i) {
    if (types.knows(config.topics[i].type)) continue;
    throw ConfigError(
        "topics[" + std::to_string(i) + "].type",
        "this bridge does not know the message type '" + config.topics[i].type + "'" + known);
  }
  for (std::size_t i = 0; i < config.services.size(); ++i) {
    if (types.knows_service(config.services[i].type)) continue;
    throw ConfigError(
        "services[" + std::to_string(i) + "].type",
        "this bridge does not know the service type '" + config.services[i].type + "'" + known);
  }
}

struct BridgedTopic {
  const TopicConfig* config;
  std::unique_ptr<TopicCounters> counters;
  std::unique_ptr<Relay> relay;
};

struct BridgedService {
  const ServiceConfig* config;
  std::unique_ptr<TopicCounters> counters;
  std::unique_ptr<Relay> relay;
};

// Waits for DDS samples on every DDS reader (from_dds topics', services' both
// ways) and relays them, on its own thread.
class DdsReceiver {
 public:
  DdsReceiver(const DdsDomain& domain, const std::vector<Relay*>& relays)
      : waitset_(check_dds(dds_create_waitset(domain.participant()), "DDS waitset")),
        stop_(check_dds(dds_create_guardcondition(domain.participant()), "DDS guard condition")) {
    check_dds(dds_waitset_attach(waitset_.get(), stop_.get(), 0), "DDS waitset");
    for (Relay* relay : relays) {
      if (relay->reader() == 0) continue;
      relays_.push_back(relay);
      check_dds(dds_waitset_attach(waitset_.get(), relay->reader(),
                                   static_cast<dds_attach_t>(relays_.size())),
                "DDS waitset");
    }
    if (!relays_.empty()) thread_ = std::thread([this] { run(); });
  }
  ~DdsReceiver() {
    stopping_ = true;
    dds_set_guardcondition(stop_.get(), true);
    if (thread_.joinable()) thread_.join();
  }
  DdsReceiver(const DdsReceiver&) = delete;
  DdsReceiver& operator=(const DdsReceiver&) = delete;

  // True when its loop turned within `limit` (or it has no reader to serve):
  // a receiver stuck in a relay for longer is not alive.
  bool alive(std::chrono::steady_clock::duration limit) const {
    if (!thread_.joinable()) return true;
    const auto last = std::chrono::steady_clock::time_point(
        std::chrono::steady_clock::duration(last_turn_.load()));
    return std::chrono::steady_clock::now() - last <= limit;
  }

 private:
  void run() {
    std::vector<dds_attach_t> triggered(relays_.size() + 1);
    while (!stopping_) {
      last_turn_ = std::chrono::steady_clock::now().time_since_epoch().count();
      const dds_return_t count =
          dds_waitset_wait(waitset_.get(), triggered.data(), triggered.size(),
                           std::chrono::nanoseconds(receiver_turn).count());
      for (dds_return_t i = 0; i < count; ++i) {
        if (triggered[i] > 0) relays_[triggered[i] - 1]->relay_available();
      }
    }
  }

  DdsEntity waitset_;
  DdsEntity stop_;
  std::vector<Relay*> relays_;
  std::atomic<bool> stopping_{false};
  std::atomic<std::chrono::steady_clock::rep> last_turn_{
      std::chrono::steady_clock::now().time_since_epoch().count()};
  std::thread thread_;
};

std::uint64_t lost_on_dds_side(dds_entity_t reader) {
  std::uint64_t lost = 0;
  dds_sample_lost_status_t lost_status{};
  if (dds_get_sample_lost_status(reader, &lost_status) == DDS_RETCODE_OK) {
    lost += lost_status.total_count;
  }
  dds_sample_rejected_status_t rejected{};
  if (dds_get_sample_rejected_status(reader, &rejected) == DDS_RETCODE_OK) {
    lost += rejected.total_count;
  }
  return lost;
}

// What the kernel dropped from the bridge's subscription before it received it.
std::uint64_t lost_on_agnocast_side(const TopicConfig& topic, std::uint32_t subscription_id) {
  try {
    const auto info = agnocast::topic_info(topic.name);
    if (!info) return 0;
    for (const auto& subscriber : info->subscribers) {
      if (subscriber.pid == ::getpid() && subscriber.id == subscription_id)
        return subscriber.dropped;
    }
  } catch (const agnocast::Error&) {
  }
  return 0;
}

BridgeStatus collect_status(const Config& config, const std::vector<BridgedTopic>& topics,
                            const std::vector<BridgedService>& services) {
  BridgeStatus status;
  status.domain_id = config.domain_id;
  for (const auto& topic : topics) {
    TopicStatus entry{topic.config, topic.counters->relayed, topic.counters->dropped,
                      topic.counters->errors};
    entry.dropped += topic.config->direction == Direction::to_dds
                         ? lost_on_agnocast_side(*topic.config, topic.relay->subscription_id())
                         : lost_on_dds_side(topic.relay->reader());
    status.topics.push_back(entry);
  }
  for (const auto& service : services) {
    status.services.push_back(BridgedServiceStatus{service.config, service.counters->relayed,
                                                   service.counters->dropped,
                                                   service.counters->errors});
  }
  return status;
}

int serve(const Config& config, const TypeRegistry& types) {
  DdsDomain domain(config.domain_id);
  // One bridge per machine: its loop protection recognizes only its own
  // process's publications, and two bridges would relay each other's.
  agnocast_service::ServiceLoop service(
      {.program = "agnocast-bridge", .status_path = std::string(agnocast::bridge_status_path)});

  agnocast::Node node(node_name);
  std::vector<BridgedTopic> topics;
  for (std::size_t i = 0; i < config.topics.size(); ++i) {
    const TopicConfig& topic = config.topics[i];
    auto counters = std::make_unique<TopicCounters>();
    const RelayContext context{topic, node, domain, *counters};
    try {
      auto relay = types.make(topic.type, topic.direction, context);
      topics.push_back(BridgedTopic{&topic, std::move(counters), std::move(relay)});
    } catch (const std::invalid_argument& error) {
      // The library refused what the topic asks for: a restart cannot fix it.
      throw ConfigError("topics[" + std::to_string(i) + "]", error.what());
    } catch (const std::exception& error) {
      throw std::runtime_error("topic " + topic.name + " (" +
                               std::string(direction_name(topic.direction)) + "): " + error.what());
    }
  }

  std::vector<BridgedService> services;
  for (std::size_t i = 0; i < config.services.size(); ++i) {
    const ServiceConfig& service = config.services[i];
    auto counters = std::make_unique<TopicCounters>();
    const ServiceRelayContext context{service, node, domain, *counters};
    try {
      auto relay = types.make_service(service.type, service.direction, context);
      services.push_back(BridgedService{&service, std::move(counters), std::move(relay)});
    } catch (const std::invalid_argument& error) {
      throw ConfigError("services[" + std::to_string(i) + "]", error.what());
    } catch (const std::exception& error) {
      // ServiceExists (from_dds: another server has the name) and the like.
      throw std::runtime_error("service " + service.name + " (" +
                               std::string(direction_name(service.direction)) +
                               "): " + error.what());
    }
  }
  std::vector<Relay*> relays;
  for (const auto& topic : topics) relays.push_back(topic.relay.get());
  for (const auto& service : services) relays.push_back(service.relay.get());

  // One loop: agnocast's subscriptions and the service's descriptor (signals,
  // the status file's timer, the watchdog's); DDS samples come on the
  // receiver's thread.
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  const DdsReceiver receiver(domain, relays);
  executor.add_fd(service.fd(), [&service, &executor] {
    if (!service.dispatch()) executor.cancel();
  });
  // Pinged from this loop, and only while the receiver's loop turns too.
  const auto receiver_limit = std::max<std::chrono::steady_clock::duration>(
      agnocast_service::watchdog_ping_interval().value_or(std::chrono::microseconds{0}),
      2 * receiver_turn);
  agnocast_service::ServiceHooks hooks;
  hooks.status_body = [&config, &topics, &services](const agnocast::ServiceStatus&) {
    return status_body(collect_status(config, topics, services));
  };
  hooks.healthy = [&receiver, receiver_limit] {
    const bool alive = receiver.alive(receiver_limit);
    if (!alive) spdlog::error("the DDS receiver is stuck; not pinging the watchdog");
    return alive;
  };
  const std::string relaying = "relaying " + std::to_string(topics.size()) + " topic(s) and " +
                               std::to_string(services.size()) + " service(s) on DDS domain " +
                               std::to_string(config.domain_id);
  spdlog::info("{}", relaying);
  service.ready(relaying, std::move(hooks));
  executor.spin();
  executor.remove_fd(service.fd());
  service.stopped();
  return 0;
}

}  // namespace

int run_bridge(int argc, char** argv, const TypeRegistry& types) {
  CLI::App app{"Relays agnocast topics to and from DDS (Cyclone DDS) as ROS 2 does.",
               "agnocast-bridge"};
  std::string config_path(default_config_path);
  bool check_only = false;
  bool list_types = false;
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_flag("--check-config", check_only,
               "Validate the configuration and exit (0 valid, 2 not)");
  app.add_flag("--list-types", list_types, "Print the message and service types this bridge knows");
  app.set_version_flag("--version",
                       "agnocast-bridge " + std::string(agnocast::library_version_string));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == EXIT_SUCCESS ? EXIT_SUCCESS : exit_usage;  // --help is no error
  }
  if (list_types) {
    for (const auto& name : types.type_names()) std::cout << name << '\n';
    for (const auto& name : types.service_type_names()) std::cout << name << '\n';
    return EXIT_SUCCESS;
  }

  agnocast_service::set_up_logging("agnocast-bridge", "info", agnocast_service::stderr_is_journal(),
                                   agnocast_service::LogStyle::tagged);
  Config config;
  try {
    config = load_config(config_path);
    check_types(config, types);
  } catch (const ConfigError& error) {
    spdlog::error("bad configuration {}: {}", config_path, error.what());
    return exit_usage;
  }
  if (check_only) {
    std::cout << "agnocast-bridge: " << config_path << " is valid (" << config.topics.size()
              << " topic(s), " << config.services.size() << " service(s))\n";
    return EXIT_SUCCESS;
  }
  try {
    // The service's signals queue for its loop from here on, before any
    // thread (Cyclone DDS's) starts: every thread inherits the mask.
    agnocast_service::block_signals(agnocast_service::service_signals());
    return serve(config, types);
  } catch (const ConfigError& error) {
    spdlog::error("bad configuration {}: {}", config_path, error.what());
    return exit_usage;
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
  }
  return exit_failure;
}

}  // namespace agnocast_bridge
