#include "bridge.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/errors.hpp"
#include "agnocast/executor.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/signals.hpp"
#include "agnocast/version.hpp"
#include "config.hpp"
#include "dds_domain.hpp"
#include "notify.hpp"
#include "status_file.hpp"

namespace agnocast_bridge {
namespace {

constexpr const char* node_name = "agnocast_bridge";
constexpr auto status_interval = std::chrono::seconds(1);

void print_usage(std::ostream& out) {
  out << "usage: agnocast-bridge [--config PATH] [--check-config] [--list-types] [--version]\n"
         "Relays agnocast topics to and from DDS (Cyclone DDS) as ROS 2 does.\n"
         "  --config PATH    configuration (default "
      << default_config_path
      << ")\n"
         "  --check-config   validate the configuration and exit (0 valid, 2 not)\n"
         "  --list-types     print the message types this bridge knows\n";
}

// Bridged topics whose type is not in the registry are configuration errors.
void check_types(const Config& config, const TypeRegistry& types) {
  for (std::size_t i = 0; i < config.topics.size(); ++i) {
    if (types.knows(config.topics[i].type)) continue;
    // The standard set alone has over a hundred types: named by --list-types, not here.
    throw ConfigError("topics[" + std::to_string(i) + "].type",
                      "this bridge does not know the message type '" + config.topics[i].type +
                          "' (--list-types shows the " + std::to_string(types.type_names().size()) +
                          " it knows; a bridge for other types is built with "
                          "agnocast_add_bridge())");
  }
}

// One bridge per machine: its loop protection recognizes only its own
// process's publications, and two bridges would relay each other's.
class InstanceLock {
 public:
  explicit InstanceLock(const std::string& path) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0 || ::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      throw std::runtime_error("another agnocast-bridge is running (it holds " + path + ")");
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd_, 0) != 0 || ::write(fd_, pid.data(), pid.size()) < 0) {
      throw std::runtime_error("cannot write " + path);
    }
  }
  ~InstanceLock() {
    if (fd_ >= 0) ::close(fd_);
  }
  InstanceLock(const InstanceLock&) = delete;
  InstanceLock& operator=(const InstanceLock&) = delete;

 private:
  int fd_ = -1;
};

struct BridgedTopic {
  const TopicConfig* config;
  std::unique_ptr<TopicCounters> counters;
  std::unique_ptr<Relay> relay;
};

// Waits for DDS samples on every from_dds reader and relays them, on its own thread.
class DdsReceiver {
 public:
  DdsReceiver(const DdsDomain& domain, const std::vector<BridgedTopic>& topics)
      : waitset_(check_dds(dds_create_waitset(domain.participant()), "DDS waitset")),
        stop_(check_dds(dds_create_guardcondition(domain.participant()), "DDS guard condition")) {
    check_dds(dds_waitset_attach(waitset_.get(), stop_.get(), 0), "DDS waitset");
    for (std::size_t i = 0; i < topics.size(); ++i) {
      if (topics[i].relay->reader() == 0) continue;
      relays_.push_back(topics[i].relay.get());
      check_dds(dds_waitset_attach(waitset_.get(), topics[i].relay->reader(),
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

 private:
  void run() {
    std::vector<dds_attach_t> triggered(relays_.size() + 1);
    while (!stopping_) {
      const dds_return_t count =
          dds_waitset_wait(waitset_.get(), triggered.data(), triggered.size(), DDS_SECS(1));
      for (dds_return_t i = 0; i < count; ++i) {
        if (triggered[i] > 0) relays_[triggered[i] - 1]->relay_available();
      }
    }
  }

  DdsEntity waitset_;
  DdsEntity stop_;
  std::vector<Relay*> relays_;
  std::atomic<bool> stopping_{false};
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
                            std::int64_t started_at, bool running) {
  BridgeStatus status;
  status.running = running;
  status.pid = ::getpid();
  status.domain_id = config.domain_id;
  status.started_at = started_at;
  status.uptime_s = static_cast<std::int64_t>(std::time(nullptr)) - started_at;
  for (const auto& topic : topics) {
    TopicStatus entry{topic.config, topic.counters->relayed, topic.counters->dropped,
                      topic.counters->errors};
    entry.dropped += topic.config->direction == Direction::to_dds
                         ? lost_on_agnocast_side(*topic.config, topic.relay->subscription_id())
                         : lost_on_dds_side(topic.relay->reader());
    status.topics.push_back(entry);
  }
  return status;
}

void write_status(const Config& config, const std::vector<BridgedTopic>& topics,
                  std::int64_t started_at, bool running) {
  try {
    write_status_file(std::string(status_path),
                      collect_status(config, topics, started_at, running));
  } catch (const std::exception& error) {
    std::cerr << "agnocast-bridge: status file: " << error.what() << std::endl;
  }
}

int serve(const Config& config, const TypeRegistry& types) {
  DdsDomain domain(config.domain_id);
  const InstanceLock lock{std::string(lock_path)};
  agnocast::install_signal_handlers();
  const auto started_at = static_cast<std::int64_t>(std::time(nullptr));

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

  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  const DdsReceiver receiver(domain, topics);
  write_status(config, topics, started_at, true);
  std::cerr << "agnocast-bridge: relaying " << topics.size() << " topic(s) on DDS domain "
            << config.domain_id << std::endl;
  notify_systemd("READY=1");

  const auto watchdog = watchdog_interval();
  auto next_status = std::chrono::steady_clock::now() + status_interval;
  auto next_watchdog = std::chrono::steady_clock::now();
  while (agnocast::ok()) {
    executor.spin_once(std::chrono::milliseconds(100));
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_status) {
      write_status(config, topics, started_at, true);
      next_status = now + status_interval;
    }
    if (watchdog && now >= next_watchdog) {
      notify_systemd("WATCHDOG=1");
      next_watchdog = now + *watchdog;
    }
  }
  notify_systemd("STOPPING=1");
  write_status(config, topics, started_at, false);
  return 0;
}

}  // namespace

int run_bridge(int argc, char** argv, const TypeRegistry& types) {
  std::string config_path(default_config_path);
  bool check_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--config" && i + 1 < argc) {
      config_path = argv[++i];
    } else if (argument == "--check-config") {
      check_only = true;
    } else if (argument == "--list-types") {
      for (const auto& name : types.type_names()) std::cout << name << '\n';
      return 0;
    } else if (argument == "--version") {
      std::cout << "agnocast-bridge " << agnocast::library_version_string << '\n';
      return 0;
    } else if (argument == "--help" || argument == "-h") {
      print_usage(std::cout);
      return 0;
    } else {
      std::cerr << "agnocast-bridge: unknown argument '" << argument << "'\n";
      print_usage(std::cerr);
      return 2;
    }
  }

  Config config;
  try {
    config = load_config(config_path);
    check_types(config, types);
  } catch (const ConfigError& error) {
    std::cerr << "agnocast-bridge: bad configuration " << config_path << ": " << error.what()
              << std::endl;
    return 2;
  }
  if (check_only) {
    std::cout << "agnocast-bridge: " << config_path << " is valid (" << config.topics.size()
              << " topic(s))\n";
    return 0;
  }
  try {
    return serve(config, types);
  } catch (const ConfigError& error) {
    std::cerr << "agnocast-bridge: bad configuration " << config_path << ": " << error.what()
              << std::endl;
    return 2;
  } catch (const DdsError& error) {
    std::cerr << "agnocast-bridge: " << error.what() << std::endl;
  } catch (const std::exception& error) {
    std::cerr << "agnocast-bridge: " << error.what() << std::endl;
  }
  return 1;
}

}  // namespace agnocast_bridge
