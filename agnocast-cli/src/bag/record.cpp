// agnocast-cli bag record [-o PATH] [--all | TOPIC...] [--compression zstd|lz4|none]
//                         [--max-size BYTES] [--duration SECONDS]
//
// One SchemaSubscription per topic, waited on with poll(). A received message
// is turned into CDR from its schema straight out of the publisher's pool and
// released at once; the file is written after the wake-up's messages are all
// back, so a slow disk never keeps a publisher's memory. What the kernel drops
// for the recorder's own subscriptions (a full queue) is read back from the
// kernel's counters and reported.
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <system_error>

#include "agnocast/inspect.hpp"
#include "agnocast/mcap/writer.hpp"
#include "agnocast/node.hpp"
#include "agnocast/schema_cdr.hpp"
#include "agnocast/schema_definition.hpp"
#include "agnocast/schema_subscription.hpp"
#include "agnocast/signals.hpp"
#include "agnocast/topic_watcher.hpp"
#include "agnocast/version.hpp"
#include "bag/bag.hpp"
#include "bag/qos_profiles.hpp"
#include "commands.hpp"

namespace agnocast::cli {
namespace {

// Deep enough for bursts, shallow enough that a stopped recorder holds little
// of a publisher's pool: the kernel drops the oldest for this subscriber only.
constexpr std::size_t record_depth = 16;
constexpr int poll_interval_ms = 100;
constexpr double status_interval_s = 0.5;
constexpr double discovery_interval_s = 1.0;

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

double steady_s() { return static_cast<double>(steady_ns()) / 1e9; }

struct Pending {
  std::uint16_t channel = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::vector<std::uint8_t> bytes;
};

struct RecordedTopic {
  std::string name;
  std::string type;
  std::string definition;
  mcap::StringMap metadata;
  std::unique_ptr<SchemaSubscription> subscription;
  std::uint16_t channel = 0;  // in the current file
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;
  std::uint64_t invalid = 0;  // messages that could not be turned into CDR or a chunk
  std::string last_problem;
};

std::string size_text(double bytes) {
  char buffer[32];
  if (bytes >= 1 << 20) {
    std::snprintf(buffer, sizeof buffer, "%.1f MiB", bytes / (1 << 20));
  } else if (bytes >= 1024) {
    std::snprintf(buffer, sizeof buffer, "%.1f KiB", bytes / 1024);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.0f B", bytes);
  }
  return buffer;
}

TopicWatcherOptions recorded_topics() {
  TopicWatcherOptions options;
  options.publishers_only = true;
  return options;
}

class Recorder {
 public:
  explicit Recorder(const BagRecordOptions& options)
      : options_(options), node_("agnocast_bag_record") {}

  // A topic named on the command line: it must exist and carry a schema.
  void add_named(const std::string& topic) {
    if (const std::string refusal = service_topic_refusal(topic); !refusal.empty()) {
      throw InputError("cannot record: " + refusal);
    }
    const std::optional<TopicInfo> info = topic_info(topic);
    if (!info) {
      throw InputError("topic '" + topic +
                       "' does not exist (no publisher or subscriber uses it); "
                       "`agnocast-cli topic list` shows the topics");
    }
    std::string problem;
    if (!add(topic, problem)) throw InputError("cannot record topic '" + topic + "': " + problem);
  }

  // --all: every typed topic with a publisher not recorded yet; those that
  // cannot be are named once.
  void discover() {
    const TopicChanges changes = watcher_.poll();
    for (const WatchedTopic& found : changes.appeared) {
      const std::string& name = found.topic.topic;
      if (recorded_.contains(name) || refused_.contains(name)) continue;
      std::string problem;
      if (!add(name, problem)) refuse(name, problem);
    }
    for (const RefusedTopic& topic : changes.refused) {
      if (!recorded_.contains(topic.name) && !refused_.contains(topic.name)) {
        refuse(topic.name, topic.problem);
      }
    }
  }

  void open(const std::string& path) {
    path_ = path;
    start_file(path);
  }

  int run(std::ostream& out) {
    const double start = steady_s();
    double last_status = start;
    double last_discovery = start;
    const bool terminal = ::isatty(STDERR_FILENO) == 1;
    while (agnocast::ok()) {
      const double now = steady_s();
      if (options_.duration_s && now - start >= *options_.duration_s) break;
      if (options_.all && now - last_discovery >= discovery_interval_s) {
        discover();
        last_discovery = now;
      }
      wait_and_receive();
      write_pending();
      if (terminal && now - last_status >= status_interval_s) {
        status_line(now - start);
        last_status = now;
      }
    }
    // What already waits is still recorded.
    for (const auto& topic : topics_) receive(*topic);
    write_pending();
    if (terminal) std::cerr << "\r\033[K";
    writer_->close();
    files_.push_back(writer_->path());
    summary(out, steady_s() - start);
    return exit_success;
  }

 private:
  void refuse(const std::string& name, const std::string& problem) {
    refused_.insert(name);
    std::cerr << "agnocast-cli: not recording topic '" << name << "': " << problem << '\n';
  }

  bool add(const std::string& name, std::string& problem) {
    auto topic = std::make_unique<RecordedTopic>();
    topic->name = name;
    RecordedTopic* raw = topic.get();
    try {
      topic->subscription = std::make_unique<SchemaSubscription>(
          node_, name, QoS(record_depth),
          [this, raw](const SchemaMessage& message, const MessageInfo& info) {
            take(*raw, message, info);
          });
      topic->type = topic->subscription->type_name();
      // Each type's own .msg text (constants and comments too), as rosbag2 writes it.
      topic->definition = ros2msg_definition(topic->subscription->schema());
    } catch (const std::exception& error) {
      problem = error.what();
      return false;
    }
    topic->metadata = channel_metadata(name);
    // What bag play needs to publish the type a compiled subscriber expects.
    char hash[17];
    std::snprintf(hash, sizeof hash, "%016llx",
                  static_cast<unsigned long long>(topic->subscription->type_hash()));
    topic->metadata["agnocast_type_hash"] = hash;
    std::string hex;
    for (const std::uint8_t byte : topic->subscription->schema_blob()) {
      static constexpr char digits[] = "0123456789abcdef";
      hex += digits[byte >> 4];
      hex += digits[byte & 0xF];
    }
    topic->metadata["agnocast_schema"] = hex;
    if (writer_) register_topic(*topic);
    recorded_.insert(name);
    topics_.push_back(std::move(topic));
    return true;
  }

  static mcap::StringMap channel_metadata(const std::string& topic) {
    std::vector<std::pair<std::uint32_t, bool>> publishers;
    if (const std::optional<TopicInfo> info = topic_info(topic)) {
      for (const PublisherInfo& publisher : info->publishers) {
        publishers.emplace_back(publisher.depth, publisher.transient_local);
      }
    }
    return {{"offered_qos_profiles", offered_qos_profiles(publishers)}};
  }

  void register_topic(RecordedTopic& topic) {
    auto schema = schemas_.find(topic.type);
    if (schema == schemas_.end()) {
      const std::uint16_t id = writer_->add_schema(
          topic.type, "ros2msg", {topic.definition.begin(), topic.definition.end()});
      schema = schemas_.emplace(topic.type, id).first;
    }
    topic.channel = writer_->add_channel(schema->second, topic.name, "cdr", topic.metadata);
  }

  void start_file(const std::string& path) {
    writer_ = std::make_unique<mcap::Writer>(
        path, mcap::WriterOptions{.profile = "ros2",
                                  .library = std::string("agnocast-cli ") + AGNOCAST_CLI_VERSION,
                                  .compression = options_.compression});
    schemas_.clear();
    for (auto& topic : topics_) register_topic(*topic);
  }

  // In the subscription's callback: copy out as CDR, nothing more.
  void take(RecordedTopic& topic, const SchemaMessage& message, const MessageInfo& info) {
    Pending pending;
    pending.channel = topic.channel;
    pending.log_time = realtime_ns();
    // The publisher stamped its steady clock; the file wants the epoch.
    const std::int64_t age = steady_ns() - info.publish_time;
    pending.publish_time = info.publish_time > 0 && age >= 0
                               ? pending.log_time - static_cast<std::uint64_t>(age)
                               : pending.log_time;
    try {
      serialize_with_schema(message.data(), topic.subscription->schema(), pending.bytes,
                            {.readable = message.readable()});
    } catch (const cdr::Error& error) {
      ++topic.invalid;
      topic.last_problem = error.what();
      return;
    }
    if (pending.bytes.size() > mcap::message_data_max) {  // no reader would take its chunk
      ++topic.invalid;
      topic.last_problem = "a message of " + std::to_string(pending.bytes.size()) +
                           " bytes of CDR: an MCAP chunk holds at most " +
                           std::to_string(mcap::message_data_max);
      return;
    }
    ++topic.messages;
    topic.bytes += pending.bytes.size();
    pending_.push_back(std::move(pending));
  }

  void receive(RecordedTopic& topic) { topic.subscription->receive(); }

  void wait_and_receive() {
    std::vector<pollfd> fds;
    for (const auto& topic : topics_) fds.push_back({topic->subscription->wait_fd(), POLLIN, 0});
    if (fds.empty()) {
      ::poll(nullptr, 0, poll_interval_ms);
      return;
    }
    if (::poll(fds.data(), fds.size(), poll_interval_ms) <= 0) return;
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if (fds[i].revents != 0) receive(*topics_[i]);
    }
  }

  void write_pending() {
    for (const Pending& pending : pending_) {
      if (options_.max_size && writer_->message_count() > 0 &&
          writer_->file_bytes() + writer_->pending_bytes() + pending.bytes.size() >
              *options_.max_size) {
        next_file();
      }
      writer_->write_message(pending.channel, pending.log_time, pending.publish_time,
                             pending.bytes);
      bytes_written_ += pending.bytes.size();
    }
    pending_.clear();
  }

  // Every file registers the topics in the order they were added, so a
  // topic's channel id is the same in each and pending messages stay valid.
  void next_file() {
    writer_->close();
    files_.push_back(writer_->path());
    const std::filesystem::path first(path_);
    const std::string next =
        (first.parent_path() /
         (first.stem().string() + "_" + std::to_string(files_.size()) + first.extension().string()))
            .string();
    start_file(next);
  }

  std::uint64_t dropped(const RecordedTopic& topic) const {
    const std::optional<TopicInfo> info = topic_info(topic.name);
    if (!info) return 0;
    for (const SubscriberInfo& subscriber : info->subscribers) {
      if (subscriber.id == topic.subscription->id()) return subscriber.dropped;
    }
    return 0;
  }

  void status_line(double elapsed) {
    std::uint64_t messages = 0;
    std::uint64_t drops = 0;
    for (const auto& topic : topics_) {
      messages += topic->messages;
      drops += dropped(*topic) + topic->invalid;
    }
    char line[256];
    std::snprintf(line, sizeof line,
                  "\r\033[Krecording %s: %zu topics, %llu messages, %s, %.1f msg/s, %llu dropped",
                  writer_->path().c_str(), topics_.size(),
                  static_cast<unsigned long long>(messages),
                  size_text(static_cast<double>(bytes_written_)).c_str(),
                  elapsed > 0 ? static_cast<double>(messages) / elapsed : 0.0,
                  static_cast<unsigned long long>(drops));
    std::cerr << line << std::flush;
  }

  void summary(std::ostream& out, double elapsed) {
    nlohmann::json topics = nlohmann::json::array();
    std::uint64_t messages = 0;
    for (const auto& topic : topics_) {
      messages += topic->messages;
      nlohmann::json entry = {{"name", topic->name},         {"type", topic->type},
                              {"messages", topic->messages}, {"bytes", topic->bytes},
                              {"dropped", dropped(*topic)},  {"invalid", topic->invalid}};
      if (!topic->last_problem.empty()) entry["last_problem"] = topic->last_problem;
      topics.push_back(entry);
    }
    const nlohmann::json value = {{"files", files_},
                                  {"duration_s", elapsed},
                                  {"messages", messages},
                                  {"bytes", bytes_written_},
                                  {"topics", topics}};
    if (options_.json) {
      out << value.dump() << '\n';
      return;
    }
    char head[128];
    std::snprintf(head, sizeof head, "Recorded %llu messages (%s) in %.1f s into:\n",
                  static_cast<unsigned long long>(messages),
                  size_text(static_cast<double>(bytes_written_)).c_str(), elapsed);
    out << head;
    for (const std::string& file : files_) out << "  " << file << '\n';
    for (const nlohmann::json& topic : topics) {
      out << "  " << topic["name"].get<std::string>() << " (" << topic["type"].get<std::string>()
          << "): " << topic["messages"] << " messages, " << topic["dropped"] << " dropped";
      if (topic["invalid"].get<std::uint64_t>() > 0) {
        out << ", " << topic["invalid"] << " not serializable ("
            << topic["last_problem"].get<std::string>() << ")";
      }
      out << '\n';
    }
  }

  const BagRecordOptions& options_;
  Node node_;
  std::vector<std::unique_ptr<RecordedTopic>> topics_;
  std::set<std::string> recorded_;
  // The same rules and definitions as agnocast-foxglove's; a recorder follows
  // topics with a publisher, and keeps recording one that goes away.
  TopicWatcher watcher_{recorded_topics()};
  std::set<std::string> refused_;
  std::map<std::string, std::uint16_t> schemas_;
  std::unique_ptr<mcap::Writer> writer_;
  std::string path_;
  std::vector<std::string> files_;
  std::vector<Pending> pending_;
  std::uint64_t bytes_written_ = 0;
};

}  // namespace

std::string bag_output_path(const std::string& output, double unix_seconds) {
  namespace fs = std::filesystem;
  char name[64];
  const auto seconds = static_cast<std::time_t>(unix_seconds);
  std::tm local{};
  ::localtime_r(&seconds, &local);
  std::strftime(name, sizeof name, "%Y-%m-%d_%H-%M-%S.mcap", &local);
  if (output.empty()) return name;
  std::error_code error;
  if (output.ends_with('/') || fs::is_directory(output, error)) {
    fs::create_directories(output, error);
    if (error) {
      throw InputError("cannot create directory " + output + ": " + error.message());
    }
    return (fs::path(output) / name).string();
  }
  return output;
}

int bag_record(const BagRecordOptions& options, std::ostream& out) {
  install_signal_handlers();
  Recorder recorder(options);
  for (const std::string& topic : options.topics) recorder.add_named(topic);
  if (options.all) recorder.discover();
  const std::string path = bag_output_path(
      options.output,
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count());
  try {
    recorder.open(path);
  } catch (const std::system_error& error) {
    throw InputError("cannot write " + path + ": " + error.code().message());
  }
  return recorder.run(out);
}

}  // namespace agnocast::cli
