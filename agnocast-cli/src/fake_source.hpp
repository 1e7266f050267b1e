// An InspectionSource made of plain data, for unit tests of the commands.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <tuple>
#include <utility>

#include "agnocast/errors.hpp"
#include "agnocast/schema_subscriber.hpp"
#include "inspection_source.hpp"

namespace agnocast::cli {

// What a subscription to one topic yields: the registered schema blob and the
// messages in place with their readable range, taken oldest first.
struct FakeStream {
  std::vector<std::uint8_t> schema;
  std::vector<std::pair<const void*, std::span<const std::byte>>> messages;
};

class FakeTap : public MessageTap {
 public:
  explicit FakeTap(FakeStream& stream) : stream_(stream), schema_(parse_schema(stream.schema)) {}
  const Schema& schema() const override { return schema_; }
  bool take(const Reader& read) override {
    if (next_ == stream_.messages.size()) return false;
    const auto& [message, readable] = stream_.messages[next_++];
    read(message, readable);
    return true;
  }

 private:
  FakeStream& stream_;  // messages may be added while subscribed
  Schema schema_;
  std::size_t next_ = 0;
};

class FakeSource : public InspectionSource {
 public:
  bool loaded = true;
  Version version = library_version;
  std::vector<TopicInfo> topics;
  std::vector<ProcessInfo> processes;
  std::optional<AccessPolicy> policy;
  std::map<std::uint32_t, std::string> users;     // uid -> name
  std::map<std::uint32_t, std::string> groups;    // gid -> name
  std::map<std::string, QueueAttributes> queues;  // by queue name ("/chatter@1")
  std::set<std::string> unreadable_queues;        // exist, but mq_open is refused
  std::set<std::string> paths;                    // that exist
  std::map<std::string, int> access_errors;       // path -> errno from access()
  std::map<std::string, std::string> files;       // path -> content
  std::set<pid_t> alive;
  std::map<std::string, bool> locks;  // path -> held exclusively
  double clock = 100.0;
  double unix_clock = 1'700'000'100.0;
  // Applied to `topics` on each sleep, to play counters advancing.
  std::function<void(FakeSource&)> on_sleep;
  std::map<std::string, FakeStream> streams;  // by topic; none: the topic has no schema
  bool stop = false;                          // SIGINT or SIGTERM arrived
  // What each subscriber's process recorded, by (pid, topic, subscriber id).
  std::map<std::tuple<pid_t, std::string, std::uint32_t>, RecordedDelays> delays;

  std::optional<Version> module_version() override {
    return loaded ? std::optional(version) : std::nullopt;
  }
  std::vector<TopicSummary> list_topics() override {
    require_module();
    std::vector<TopicSummary> list;
    for (const TopicInfo& t : topics) {
      list.push_back({t.name, static_cast<std::uint32_t>(t.publishers.size()),
                      static_cast<std::uint32_t>(t.subscribers.size()), t.type_name, t.type_hash});
    }
    return list;
  }
  std::vector<ProcessInfo> list_processes() override {
    require_module();
    return processes;
  }
  std::optional<TopicInfo> topic_info(const std::string& topic) override {
    require_module();
    for (const TopicInfo& t : topics) {
      if (t.name == topic) return t;
    }
    return std::nullopt;
  }
  std::optional<AccessPolicy> access_policy() override {
    require_module();
    return policy;
  }
  std::optional<std::string> user_name(std::uint32_t uid) override { return name_of(users, uid); }
  std::optional<std::string> group_name(std::uint32_t gid) override { return name_of(groups, gid); }
  std::vector<std::string> queue_files() override {
    std::vector<std::string> names;
    for (const auto& [name, attributes] : queues) names.push_back(name.substr(1));
    return names;
  }
  std::optional<QueueAttributes> queue_attributes(const std::string& name) override {
    const auto it = queues.find(name);
    return it == queues.end() || unreadable_queues.count(name) > 0 ? std::nullopt
                                                                   : std::optional(it->second);
  }
  bool path_exists(const std::string& path) override { return paths.count(path) > 0; }
  int path_access(const std::string& path, int) override {
    const auto it = access_errors.find(path);
    return it == access_errors.end() ? 0 : it->second;
  }
  std::optional<std::string> read_file(const std::string& path) override {
    const auto it = files.find(path);
    return it == files.end() ? std::nullopt : std::optional(it->second);
  }
  bool process_alive(pid_t pid) override { return alive.count(pid) > 0; }
  std::optional<bool> exclusively_locked(const std::string& path) override {
    const auto it = locks.find(path);
    return it == locks.end() ? std::nullopt : std::optional(it->second);
  }
  std::unique_ptr<MessageTap> subscribe(const std::string& topic) override {
    if (!topic_info(topic)) throw TopicWithoutSchema("no publisher or subscriber uses " + topic);
    const auto stream = streams.find(topic);
    if (stream == streams.end()) throw TopicWithoutSchema(topic + " has no schema");
    return std::make_unique<FakeTap>(stream->second);
  }
  Schema topic_schema(const std::string& topic) override {
    if (!topic_info(topic)) throw TopicWithoutSchema("no publisher or subscriber uses " + topic);
    const auto stream = streams.find(topic);
    if (stream == streams.end()) throw TopicWithoutSchema(topic + " has no schema");
    return parse_schema(stream->second.schema);
  }
  std::optional<RecordedDelays> recorded_delays(pid_t pid, const std::string& topic,
                                                std::uint32_t subscriber_id) override {
    const auto it = delays.find({pid, topic, subscriber_id});
    return it == delays.end() ? std::nullopt : std::optional(it->second);
  }
  bool stop_requested() override { return stop; }
  double now_seconds() override { return clock; }
  double unix_time() override { return unix_clock; }
  void sleep_seconds(double seconds) override {
    clock += seconds;
    if (on_sleep) on_sleep(*this);
  }

 private:
  void require_module() const {
    if (!loaded) throw ModuleNotLoaded();
  }
  static std::optional<std::string> name_of(const std::map<std::uint32_t, std::string>& names,
                                            std::uint32_t id) {
    const auto it = names.find(id);
    return it == names.end() ? std::nullopt : std::optional(it->second);
  }
};

// A healthy system: /chatter with one talker (pid 100), a callback listener
// (pid 200, queue /chatter@1 holding 3 wake-ups) and a polling one (pid 300).
inline FakeSource healthy_system() {
  FakeSource source;
  TopicInfo chatter;
  chatter.name = "/chatter";
  chatter.type_name = "chatter/msg/Message";
  chatter.type_hash = 0x31d0e2409f905facULL;
  PublisherInfo talker;
  talker.id = 0;
  talker.pid = 100;
  talker.node = "talker";
  talker.depth = 10;
  talker.published = 42;
  talker.published_bytes = 42 * 1024;
  talker.window = 4;
  talker.uid = 1000;
  chatter.publishers.push_back(talker);
  SubscriberInfo listener;
  listener.id = 1;
  listener.pid = 200;
  listener.node = "listener";
  listener.depth = 10;
  listener.unreceived = 3;
  listener.dropped = 1;
  listener.held = 2;
  listener.received = 37;
  listener.uid = 1001;
  chatter.subscribers.push_back(listener);
  SubscriberInfo poller;
  poller.id = 2;
  poller.pid = 300;
  poller.node = "poller";
  poller.depth = 1;
  poller.polling = true;
  poller.transient_local = true;
  poller.uid = 1001;
  chatter.subscribers.push_back(poller);
  source.topics.push_back(chatter);
  // The talker's pool: 64 MiB at slot 0, 3 MiB of it resident.
  ProcessInfo talker_process;
  talker_process.pid = 100;
  talker_process.publishers = 1;
  talker_process.pool_addr = 0x40000000000;
  talker_process.pool_size = 64 << 20;
  source.processes.push_back(talker_process);
  for (const pid_t subscriber : {200, 300}) {
    ProcessInfo process;
    process.pid = subscriber;
    process.subscribers = 1;
    process.pools_mapped = 1;
    source.processes.push_back(process);
  }
  source.files["/proc/100/status"] = "Name:\ttalker\nUid:\t1000\t1000\t1000\t1000\n";
  source.files["/proc/200/status"] = "Name:\tlistener\nUid:\t1001\t1001\t1001\t1001\n";
  source.files["/proc/100/smaps"] =
      "55d0c0000000-55d0c0001000 r-xp 00000000 08:01 1 /usr/bin/agnocast-talker\n"
      "Size:                  4 kB\nRss:                   4 kB\n"
      "40000000000-40004000000 rw-s 00000000 00:01 7 /memfd:agnocast-pool (deleted)\n"
      "Size:              65536 kB\nRss:                3072 kB\nPss:                3072 kB\n";
  source.queues["/chatter@1"] = {3, 10};
  source.paths = {"/sys/module/agnocast", "/dev/agnocast"};
  source.files["/proc/mounts"] =
      "proc /proc proc rw 0 0\nmqueue /dev/mqueue mqueue rw,relatime 0 0\n";
  source.files["/proc/sys/fs/mqueue/msg_max"] = "10\n";
  source.files["/proc/sys/fs/mqueue/queues_max"] = "256\n";
  source.files["/run/agnocast/agnocastd.json"] =
      R"({"running":true,"pid":50,"module_loaded":true,"module_version":"0.1.0",)"
      R"("uptime_s":12,"started_at":1700000000,"processes_cleaned":2,"queues_removed":3,)"
      R"("shm_removed":0})";
  source.locks["/run/agnocast/agnocastd.lock"] = true;
  source.files["/proc/50/comm"] = "agnocastd\n";
  source.alive = {50, 100, 200, 300};
  return source;
}

// healthy_system() with service /arm/enable (std_srvs/srv/SetBool): server
// node arm_driver (pid 400) and three clients: one of node panel (pid 500),
// two of node planner (pid 600), each a reply subscriber and then a request
// publisher, ids in the order the library creates them.
inline FakeSource system_with_service() {
  FakeSource source = healthy_system();
  TopicInfo request;
  request.name = "/_service_request/arm/enable";
  request.type_name = "std_srvs/srv/SetBool_Request";
  request.type_hash = 0x1111;
  TopicInfo reply;
  reply.name = "/_service_reply/arm/enable";
  reply.type_name = "std_srvs/srv/SetBool_Response";
  reply.type_hash = 0x2222;
  SubscriberInfo server_requests;
  server_requests.id = 10;
  server_requests.pid = 400;
  server_requests.node = "arm_driver";
  server_requests.depth = 10;
  server_requests.received = 12;
  server_requests.dropped = 2;
  server_requests.uid = 1002;
  request.subscribers.push_back(server_requests);
  PublisherInfo server_replies;
  server_replies.id = 11;
  server_replies.pid = 400;
  server_replies.node = "arm_driver";
  server_replies.depth = 10;
  server_replies.published = 12;
  server_replies.uid = 1002;
  reply.publishers.push_back(server_replies);
  // {pid, node, reply subscriber id, calls, answers received, answers unreceived}
  const struct {
    pid_t pid;
    const char* node;
    std::uint32_t id;
    std::uint64_t calls;
    std::uint64_t received;
    std::uint32_t unreceived;
  } clients[] = {
      {600, "planner", 16, 1, 0, 0}, {500, "panel", 12, 5, 4, 1}, {600, "planner", 14, 8, 5, 0}};
  for (const auto& c : clients) {
    SubscriberInfo answers;
    answers.id = c.id;
    answers.pid = c.pid;
    answers.node = c.node;
    answers.depth = 10;
    answers.received = c.received;
    answers.unreceived = c.unreceived;
    answers.uid = 1003;
    reply.subscribers.push_back(answers);
    PublisherInfo calls;
    calls.id = c.id + 1;
    calls.pid = c.pid;
    calls.node = c.node;
    calls.depth = 10;
    calls.published = c.calls;
    calls.uid = 1003;
    request.publishers.push_back(calls);
  }
  source.topics.push_back(request);
  source.topics.push_back(reply);
  // Each callback subscriber's queue: the server's and the clients'.
  source.queues["/_service_request_arm_enable@10"] = {0, 10};
  for (const auto& c : clients) {
    source.queues["/_service_reply_arm_enable@" + std::to_string(c.id)] = {0, 10};
  }
  return source;
}

}  // namespace agnocast::cli
