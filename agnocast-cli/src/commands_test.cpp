// The commands' JSON values and tables, built from fake system state.
#include "commands.hpp"

#include <gtest/gtest.h>

#include "agnocast/errors.hpp"
#include "agnocast/service_access.hpp"
#include "fake_source.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

std::vector<std::string> keys_of(const json& object) {
  std::vector<std::string> keys;
  for (const auto& item : object.items()) keys.push_back(item.key());
  std::sort(keys.begin(), keys.end());
  return keys;
}

TEST(TopicList, CountsEndpointsPerTopicSortedByName) {
  FakeSource source = healthy_system();
  TopicInfo early;
  early.name = "/a";
  source.topics.push_back(early);
  const json value = topic_list_json(source);
  EXPECT_EQ(value,
            json::parse(R"({"topics":[{"name":"/a","type":null,"publishers":0,"subscribers":0},
                        {"name":"/chatter","type":"chatter/msg/Message","publishers":1,
                         "subscribers":2}]})"));
  EXPECT_EQ(topic_list_table(value),
            "NAME      TYPE                 PUBLISHERS  SUBSCRIBERS\n"
            "/a        -                             0            0\n"
            "/chatter  chatter/msg/Message           1            2\n");
}

TEST(TopicList, ModuleAbsentThrowsModuleNotLoaded) {
  FakeSource source;
  source.loaded = false;
  EXPECT_THROW(topic_list_json(source), ModuleNotLoaded);
}

TEST(TopicInfo, HasSpecFieldsQueueDepthFromMqueueAndNullQueueForPolling) {
  FakeSource source = healthy_system();
  const json value = topic_info_json(source, "/chatter");
  EXPECT_EQ(keys_of(value),
            (std::vector<std::string>{"name", "publishers", "subscribers", "type", "type_hash"}));
  EXPECT_EQ(value["type"], "chatter/msg/Message");
  EXPECT_EQ(value["type_hash"], "31d0e2409f905fac");
  EXPECT_EQ(value["publishers"][0],
            json::parse(R"({"id":0,"pid":100,"uid":1000,"node":"talker","depth":10,
                            "transient_local":false,"published":42})"));
  EXPECT_EQ(value["subscribers"][0],
            json::parse(R"({"id":1,"pid":200,"uid":1001,"node":"listener","depth":10,
                            "transient_local":false,"polling":false,"queue":"/chatter@1",
                            "pending":3,"unreceived":3,"held":2,"received":37,"dropped":1})"));
  EXPECT_EQ(value["subscribers"][1]["polling"], true);
  EXPECT_EQ(value["subscribers"][1]["transient_local"], true);
  EXPECT_TRUE(value["subscribers"][1]["queue"].is_null());
  EXPECT_TRUE(value["subscribers"][1]["pending"].is_null());
}

TEST(TopicInfo, TableShowsBothSections) {
  FakeSource source = healthy_system();
  EXPECT_EQ(topic_info_table(topic_info_json(source, "/chatter")),
            "topic /chatter\n"
            "type  chatter/msg/Message (31d0e2409f905fac)\n"
            "\n"
            "publishers\n"
            "ID  PID   UID  NODE    DEPTH  TRANSIENT_LOCAL  PUBLISHED\n"
            " 0  100  1000  talker     10  no                      42\n"
            "\n"
            "subscribers\n"
            "ID  PID   UID  NODE      DEPTH  TRANSIENT_LOCAL  QUEUE       PENDING  UNRECEIVED  "
            "HELD  RECEIVED  DROPPED\n"
            " 1  200  1001  listener     10  no               /chatter@1        3           3  "
            "   2        37        1\n"
            " 2  300  1001  poller        1  yes              (polling)         -           0  "
            "   0         0        0\n");
}

TEST(TopicInfo, UnknownTopicIsARuntimeErrorNamingTopicList) {
  FakeSource source = healthy_system();
  try {
    topic_info_json(source, "/nope");
    FAIL() << "expected CliError";
  } catch (const CliError& e) {
    EXPECT_NE(std::string(e.what()).find("/nope"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("topic list"), std::string::npos);
  }
}

TEST(QueueList, LiveQueueHasOwnerAndDepthStaleQueueHasNulls) {
  FakeSource source = healthy_system();
  source.queues["/ghost@7"] = {0, 10};
  source.queues["/not-agnocast"] = {0, 10};
  const json value = queue_list_json(source);
  EXPECT_EQ(value, json::parse(R"({"queues":[
      {"name":"/chatter@1","topic":"/chatter","subscriber_id":1,"pid":200,"pending":3,
       "capacity":10,"stale":false},
      {"name":"/ghost@7","topic":null,"subscriber_id":7,"pid":null,"pending":0,
       "capacity":10,"stale":true}]})"));
  EXPECT_EQ(queue_list_table(value),
            "NAME        TOPIC     SUBSCRIBER_ID  PID  PENDING  CAPACITY  STALE\n"
            "/chatter@1  /chatter              1  200        3        10  no\n"
            "/ghost@7    -                     7    -        0        10  yes\n");
}

TEST(QueueList, QueueOfAnotherTopicsSubscriberIdIsStale) {
  FakeSource source = healthy_system();
  source.queues["/chatter@2"] = {0, 1};  // id 2 is the polling subscriber: it owns no queue
  const json value = queue_list_json(source);
  ASSERT_EQ(value["queues"].size(), 2u);
  EXPECT_TRUE(value["queues"][1]["stale"].get<bool>());
}

TEST(QueueList, WithoutTheModuleEveryQueueIsStale) {
  FakeSource source = healthy_system();
  source.loaded = false;
  const json value = queue_list_json(source);
  ASSERT_EQ(value["queues"].size(), 1u);
  EXPECT_TRUE(value["queues"][0]["stale"].get<bool>());
}

TEST(QueueList, UnreadableQueueHasNullDepth) {
  FakeSource source = healthy_system();
  source.unreadable_queues.insert("/chatter@1");
  const json value = queue_list_json(source);
  ASSERT_EQ(value["queues"].size(), 1u);
  EXPECT_TRUE(value["queues"][0]["pending"].is_null());
  EXPECT_TRUE(value["queues"][0]["capacity"].is_null());
  EXPECT_FALSE(value["queues"][0]["stale"].get<bool>());
  EXPECT_TRUE(topic_info_json(source, "/chatter")["subscribers"][0]["pending"].is_null());
}

TEST(NodeList, GroupsEndpointsByProcessAndLabel) {
  FakeSource source = healthy_system();
  TopicInfo status;
  status.name = "/status";
  PublisherInfo also_talker;
  also_talker.pid = 100;
  also_talker.node = "talker";
  status.publishers.push_back(also_talker);
  SubscriberInfo other_label;  // same process, another node label
  other_label.pid = 100;
  other_label.node = "monitor";
  status.subscribers.push_back(other_label);
  source.topics.push_back(status);
  const json value = node_list_json(source);
  EXPECT_EQ(value, json::parse(R"({"nodes":[
      {"name":"monitor","pid":100,"publishes":[],"subscribes":["/status"],"serves":[],"calls":[]},
      {"name":"talker","pid":100,"publishes":["/chatter","/status"],"subscribes":[],"serves":[],
       "calls":[]},
      {"name":"listener","pid":200,"publishes":[],"subscribes":["/chatter"],"serves":[],
       "calls":[]},
      {"name":"poller","pid":300,"publishes":[],"subscribes":["/chatter"],"serves":[],
       "calls":[]}]})"));
  EXPECT_EQ(node_list_table(value),
            "NAME      PID  PUBLISHES         SUBSCRIBES  SERVES  CALLS\n"
            "monitor   100  -                 /status     -       -\n"
            "talker    100  /chatter,/status  -           -       -\n"
            "listener  200  -                 /chatter    -       -\n"
            "poller    300  -                 /chatter    -       -\n");
}

TEST(NodeInfo, PidsAndTopicsWithTypesOfOneLabel) {
  FakeSource source = healthy_system();
  TopicInfo status;
  status.name = "/status";
  PublisherInfo second_talker;  // the same label in another process
  second_talker.pid = 101;
  second_talker.node = "talker";
  status.publishers.push_back(second_talker);
  source.topics.push_back(status);
  const json value = node_info_json(source, "talker");
  EXPECT_EQ(value, json::parse(R"({"name":"talker","pids":[100,101],
      "publishers":[{"topic":"/chatter","type":"chatter/msg/Message"},
                    {"topic":"/status","type":null}],
      "subscribers":[],"servers":[],"clients":[]})"));
  EXPECT_EQ(node_info_table(value),
            "node talker\n"
            "pids 100,101\n"
            "\n"
            "DIRECTION  TOPIC     TYPE\n"
            "publishes  /chatter  chatter/msg/Message\n"
            "publishes  /status   -\n");
}

TEST(NodeInfo, AnUnknownNodeIsARuntimeErrorNamingNodeList) {
  FakeSource source = healthy_system();
  try {
    node_info_json(source, "nobody");
    FAIL() << "expected CliError";
  } catch (const CliError& e) {
    EXPECT_NE(std::string(e.what()).find("'nobody'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("node list"), std::string::npos);
  }
}

TEST(ProcessList, NodesUidAndPoolUsage) {
  FakeSource source = healthy_system();
  const json value = process_list_json(source);
  EXPECT_EQ(value, json::parse(R"({"processes":[
      {"pid":100,"uid":1000,"nodes":["talker"],"publishers":1,"subscribers":0,
       "pool":{"size":67108864,"used":3145728,"messages":4}},
      {"pid":200,"uid":1001,"nodes":["listener"],"publishers":0,"subscribers":1,"pool":null},
      {"pid":300,"uid":null,"nodes":["poller"],"publishers":0,"subscribers":1,"pool":null}]})"));
  EXPECT_EQ(process_list_table(value),
            "PID   UID  NODES     PUBLISHERS  SUBSCRIBERS  POOL_SIZE  POOL_USED  MESSAGES\n"
            "100  1000  talker             1            0   67108864    3145728         4\n"
            "200  1001  listener           0            1          -          -         -\n"
            "300     -  poller             0            1          -          -         -\n");
}

TEST(ProcessList, PoolUseIsNullWhenProcDoesNotTell) {
  FakeSource source = healthy_system();
  source.files.erase("/proc/100/smaps");
  EXPECT_TRUE(process_list_json(source)["processes"][0]["pool"]["used"].is_null());
}

TEST(DaemonStatus, RunningDaemonReportsItsStatusFile) {
  FakeSource source = healthy_system();
  const json value = daemon_status_json(source, "/run/agnocast/agnocastd.json");
  EXPECT_EQ(value, json::parse(R"({"running":true,"pid":50,"module_loaded":true,
      "module_version":"0.1.0","uptime_s":100,"processes_cleaned":2,"queues_removed":3,
      "shm_removed":0})"));
  EXPECT_EQ(daemon_status_table(value).rfind("running            yes\npid                50\n", 0),
            0u);
}

TEST(DaemonStatus, ReleasedLockMeansACrashedDaemonNotRunningWithLiveModuleState) {
  FakeSource source = healthy_system();
  source.locks["/run/agnocast/agnocastd.lock"] = false;
  const json value = daemon_status_json(source, "/run/agnocast/agnocastd.json");
  EXPECT_FALSE(value["running"].get<bool>());
  EXPECT_TRUE(value["pid"].is_null());
  EXPECT_TRUE(value["module_loaded"].get<bool>());
  EXPECT_EQ(value["module_version"], library_version.to_string());
  EXPECT_TRUE(value["processes_cleaned"].is_null());
  EXPECT_EQ(keys_of(value).size(), 8u);
}

TEST(DaemonStatus, CleanStopWritesRunningFalse) {
  FakeSource source = healthy_system();
  source.files["/run/agnocast/agnocastd.json"] = R"({"running":false,"pid":50})";
  EXPECT_FALSE(daemon_status_json(source, "/run/agnocast/agnocastd.json")["running"].get<bool>());
}

TEST(DaemonStatus, WithoutLockFileFallsBackToThePid) {
  FakeSource source = healthy_system();
  source.locks.clear();
  EXPECT_TRUE(daemon_status_json(source, "/run/agnocast/agnocastd.json")["running"].get<bool>());
  source.files["/proc/50/comm"] = "bash\n";  // the pid was reused by another program
  EXPECT_FALSE(daemon_status_json(source, "/run/agnocast/agnocastd.json")["running"].get<bool>());
  source.files.erase("/proc/50/comm");
  source.alive.erase(50);
  EXPECT_FALSE(daemon_status_json(source, "/run/agnocast/agnocastd.json")["running"].get<bool>());
}

TEST(DaemonStatus, LockFileIsLookedForBesideAnOverriddenStatusFile) {
  FakeSource source = healthy_system();
  source.files["/tmp/x/agnocastd.json"] = source.files["/run/agnocast/agnocastd.json"];
  source.locks["/tmp/x/agnocastd.lock"] = false;
  EXPECT_FALSE(daemon_status_json(source, "/tmp/x/agnocastd.json")["running"].get<bool>());
}

TEST(DaemonStatus, MissingOrGarbledFileMeansNotRunning) {
  FakeSource source = healthy_system();
  source.loaded = false;
  EXPECT_FALSE(daemon_status_json(source, "/missing.json")["running"].get<bool>());
  source.files["/bad.json"] = "{not json";
  const json value = daemon_status_json(source, "/bad.json");
  EXPECT_FALSE(value["running"].get<bool>());
  EXPECT_FALSE(value["module_loaded"].get<bool>());
  EXPECT_TRUE(value["module_version"].is_null());
  source.files["/typo.json"] = R"({"running":"yes","pid":50})";
  EXPECT_FALSE(daemon_status_json(source, "/typo.json")["running"].get<bool>());
}

// A status file as the service kit writes it: the head, then the daemon's fields.
std::string service_file(const std::string& program, pid_t pid, const std::string& fields,
                         ServiceState state = ServiceState::running) {
  std::string text =
      to_json(ServiceStatus{program, pid, "0.1.0", state, 1700000000, 12, 1700000012});
  text.replace(text.rfind('}'), 1, "," + fields + "}");
  return text;
}

// healthy_system() with agnocast-bridge running as pid 60.
FakeSource system_with_bridge() {
  FakeSource source = healthy_system();
  source.files["/run/agnocast/bridge.json"] = service_file(
      "agnocast-bridge", 60,
      R"("domain_id":0,"topics":[{"name":"/points","relayed":120,"dropped":0,"errors":0}])");
  source.locks["/run/agnocast/bridge.lock"] = true;
  source.alive.insert(60);
  return source;
}

TEST(DaemonStatus, TheOtherDaemonsBesideAgnocastdsUnchangedFields) {
  FakeSource source = system_with_bridge();
  const json value = daemon_status_command_json(source, {});
  json agnocastd = value;
  agnocastd.erase("bridge");
  agnocastd.erase("foxglove");
  EXPECT_EQ(agnocastd, daemon_status_json(source, "/run/agnocast/agnocastd.json"));

  const json& bridge = value["bridge"];
  EXPECT_EQ(bridge["running"], true);
  EXPECT_EQ(bridge["pid"], 60);
  EXPECT_EQ(bridge["program"], "agnocast-bridge");
  EXPECT_EQ(bridge["state"], "running");
  EXPECT_EQ(bridge["version"], "0.1.0");
  EXPECT_EQ(bridge["uptime_s"], 100);  // as of now, from started_at
  EXPECT_EQ(bridge["topics"][0]["relayed"], 120);
  EXPECT_EQ(value["foxglove"], json::parse(R"({"running":false,"pid":null,"uptime_s":null})"));
}

TEST(DaemonStatus, AnotherDaemonRunsOnlyWhileItHoldsItsLock) {
  FakeSource source = system_with_bridge();
  source.locks["/run/agnocast/bridge.lock"] = false;  // crashed
  EXPECT_EQ(service_status_json(source, "/run/agnocast/bridge.json", "agnocast-bridge")["running"],
            false);
  // Without a lock file to open, a live pid of that program.
  source.locks.erase("/run/agnocast/bridge.lock");
  EXPECT_EQ(service_status_json(source, "/run/agnocast/bridge.json", "agnocast-bridge")["running"],
            true);
  source.files["/proc/60/comm"] = "bash\n";
  EXPECT_EQ(service_status_json(source, "/run/agnocast/bridge.json", "agnocast-bridge")["running"],
            false);
  source.files.erase("/proc/60/comm");
  source.alive.erase(60);
  EXPECT_EQ(service_status_json(source, "/run/agnocast/bridge.json", "agnocast-bridge")["running"],
            false);
}

TEST(DaemonStatus, ProcCutsTheProgramNameTo15Characters) {
  FakeSource source = healthy_system();
  source.files["/run/agnocast/foxglove.json"] =
      service_file("agnocast-foxglove", 70, R"("port":8765)");
  source.alive.insert(70);
  source.files["/proc/70/comm"] = "agnocast-foxglo\n";
  const json foxglove =
      service_status_json(source, "/run/agnocast/foxglove.json", "agnocast-foxglove");
  EXPECT_EQ(foxglove["running"], true);
  EXPECT_EQ(foxglove["port"], 8765);
}

TEST(DaemonStatus, AStoppedOrGarbledFileOfAnotherDaemonMeansNotRunning) {
  FakeSource source = system_with_bridge();
  source.files["/run/agnocast/bridge.json"] =
      service_file("agnocast-bridge", 60, R"("topics":[])", ServiceState::stopped);
  EXPECT_EQ(service_status_json(source, "/run/agnocast/bridge.json", "agnocast-bridge")["running"],
            false);
  source.files["/run/agnocast/bridge.json"] = R"({"running":true,"pid":60})";  // no head
  EXPECT_EQ(service_status_json(source, "/run/agnocast/bridge.json", "agnocast-bridge")["running"],
            false);
  source.files["/run/agnocast/bridge.json"] = "{not json";
  EXPECT_EQ(service_status_json(source, "/run/agnocast/bridge.json", "agnocast-bridge")["running"],
            false);
}

TEST(DaemonStatus, TheTableEndsWithARowPerOtherDaemon) {
  FakeSource source = system_with_bridge();
  const std::string table = daemon_status_table(daemon_status_command_json(source, {}));
  EXPECT_EQ(table.rfind("running            yes\npid                50\n", 0), 0u);
  EXPECT_NE(table.find("shm_removed        0\n\n"
                       "DAEMON             RUNNING  STATE    PID  UPTIME_S  VERSION\n"
                       "agnocast-bridge    yes      running   60       100  0.1.0\n"
                       "agnocast-foxglove  no       -          -         -  -\n"),
            std::string::npos)
      << table;
}

const json& check_named(const json& doctor, const std::string& name) {
  for (const json& c : doctor["checks"]) {
    if (c["name"] == name) return c;
  }
  throw std::runtime_error("no check " + name);
}

TEST(Doctor, HealthySystemPassesEveryCheck) {
  FakeSource source = healthy_system();
  const json value = doctor_json(source, "/run/agnocast/agnocastd.json");
  ASSERT_EQ(value["checks"].size(), 6u);
  for (const json& c : value["checks"]) {
    EXPECT_EQ(keys_of(c), (std::vector<std::string>{"detail", "name", "ok"}));
    EXPECT_TRUE(c["ok"].get<bool>()) << c.dump();
  }
}

TEST(Doctor, ModuleAbsentFailsModuleDeviceVersionWithTheFix) {
  FakeSource source = healthy_system();
  source.loaded = false;
  source.paths.clear();
  const json value = doctor_json(source, "/run/agnocast/agnocastd.json");
  for (const char* name : {"module", "device", "version"}) {
    EXPECT_FALSE(check_named(value, name)["ok"].get<bool>()) << name;
  }
  EXPECT_NE(
      check_named(value, "module")["detail"].get<std::string>().find("systemctl start agnocastd"),
      std::string::npos);
  EXPECT_TRUE(check_named(value, "mqueue_mount")["ok"].get<bool>());
}

TEST(Doctor, IncompatibleModuleVersionFails) {
  FakeSource source = healthy_system();
  source.version.minor += 1;
  EXPECT_FALSE(check_named(doctor_json(source, "/x"), "version")["ok"].get<bool>());
}

TEST(Doctor, PatchDifferenceIsCompatible) {
  FakeSource source = healthy_system();
  source.version.patch += 1;
  EXPECT_TRUE(check_named(doctor_json(source, "/x"), "version")["ok"].get<bool>());
}

TEST(Doctor, InaccessibleDeviceFails) {
  FakeSource source = healthy_system();
  source.access_errors["/dev/agnocast"] = EACCES;
  const json doctor = doctor_json(source, "/x");
  const json& device = check_named(doctor, "device");
  EXPECT_FALSE(device["ok"].get<bool>());
  EXPECT_NE(device["detail"].get<std::string>().find("Permission denied"), std::string::npos);
}

TEST(Doctor, MqueueNotMountedFails) {
  FakeSource source = healthy_system();
  source.files["/proc/mounts"] = "proc /proc proc rw 0 0\n";
  EXPECT_FALSE(check_named(doctor_json(source, "/x"), "mqueue_mount")["ok"].get<bool>());
}

TEST(Doctor, LoweredOrExhaustedMqueueLimitsFail) {
  FakeSource source = healthy_system();
  source.files["/proc/sys/fs/mqueue/msg_max"] = "4\n";
  EXPECT_FALSE(check_named(doctor_json(source, "/x"), "mqueue_limits")["ok"].get<bool>());
  source = healthy_system();
  source.files["/proc/sys/fs/mqueue/queues_max"] = "256\n";
  for (int i = 0; i < 256; ++i) source.queues["/q@" + std::to_string(i)] = {};
  EXPECT_FALSE(check_named(doctor_json(source, "/x"), "mqueue_limits")["ok"].get<bool>());
}

TEST(Doctor, DaemonNotRunningFails) {
  FakeSource source = healthy_system();
  EXPECT_FALSE(check_named(doctor_json(source, "/missing.json"), "daemon")["ok"].get<bool>());
}

TEST(Doctor, AStatusFileLackingAFieldIsNamed) {
  FakeSource source = healthy_system();
  source.files["/typo.json"] = R"({"running":true,"pdi":50})";
  const json daemon = check_named(doctor_json(source, "/typo.json"), "daemon");
  EXPECT_FALSE(daemon["ok"].get<bool>());
  EXPECT_EQ(daemon["detail"],
            "agnocastd is not running (/typo.json: agnocastd status file: \"pid\" is missing): "
            "start it with `systemctl start agnocastd`");
  EXPECT_EQ(check_named(doctor_json(source, "/missing.json"), "daemon")["detail"],
            "agnocastd is not running: start it with `systemctl start agnocastd`");
}

TEST(Version, ModuleIsNullWhenNotLoaded) {
  FakeSource source;
  source.loaded = false;
  const json value = version_json(source);
  EXPECT_EQ(value["library"], std::string(library_version_string));
  EXPECT_EQ(value["cli"], std::string(library_version_string));
  EXPECT_TRUE(value["module"].is_null());
  EXPECT_EQ(keys_of(value), (std::vector<std::string>{"cli", "library", "module"}));
}

FakeSource policy_system() {
  using Kind = AccessPrincipal::Kind;
  FakeSource source = healthy_system();
  source.users = {{0, "root"}, {1000, "monitor"}};
  source.groups = {{990, "agnocast"}, {991, "safety"}};
  source.policy = AccessPolicy{
      true,
      {{"/safety/**", std::vector<AccessPrincipal>{{Kind::group, 991}},
        std::vector<AccessPrincipal>{{Kind::group, 990}, {Kind::user, 1000}}},
       {"/private/*", std::vector<AccessPrincipal>{{Kind::user, 1234}, {Kind::group, 4321}},
        std::vector<AccessPrincipal>{}},
       {"/open", std::nullopt, std::vector<AccessPrincipal>{{Kind::anyone, 0}}}}};
  return source;
}

TEST(PolicyShow, NullWithoutAPolicy) {
  FakeSource source = healthy_system();
  EXPECT_EQ(policy_show_json(source), json::parse(R"({"policy": null})"));
  EXPECT_EQ(policy_show_table(policy_show_json(source)),
            "no topic access policy: anyone with access to /dev/agnocast may publish and "
            "subscribe\n");
}

TEST(PolicyShow, RulesInOrderWithNamesOrIdsAndNullForUnlistedDirections) {
  FakeSource source = policy_system();
  EXPECT_EQ(policy_show_json(source), json::parse(R"({"policy": {"default": "allow", "rules": [
    {"topics": "/safety/**", "publish": ["group:safety"],
     "subscribe": ["group:agnocast", "user:monitor"]},
    {"topics": "/private/*", "publish": ["user:1234", "group:4321"], "subscribe": []},
    {"topics": "/open", "publish": null, "subscribe": ["*"]}]}})"));
}

TEST(PolicyShow, TableGoldenText) {
  FakeSource source = policy_system();
  EXPECT_EQ(policy_show_table(policy_show_json(source)),
            "default: allow (what no rule matches, and rights a rule leaves open)\n"
            "RULE               PUBLISH               SUBSCRIBE\n"
            "topics /safety/**  group:safety          group:agnocast,user:monitor\n"
            "topics /private/*  user:1234,group:4321  (nobody)\n"
            "topics /open       (default)             *\n");
  source.policy = AccessPolicy{false, {}};
  EXPECT_EQ(policy_show_json(source),
            json::parse(R"({"policy": {"default": "deny", "rules": []}})"));
  EXPECT_EQ(policy_show_table(policy_show_json(source)),
            "default: deny (what no rule matches, and rights a rule leaves open)\n"
            "no rules\n");
}

// policy_system() with a services rule between its topic rules and one for every service.
FakeSource policy_system_with_services() {
  using Kind = AccessPrincipal::Kind;
  FakeSource source = policy_system();
  std::vector<AccessRule>& rules = source.policy->rules;
  const auto arm = topic_rules_of({"/arm/*", std::vector<AccessPrincipal>{{Kind::user, 0}},
                                   std::vector<AccessPrincipal>{{Kind::group, 990}}});
  rules.insert(rules.begin() + 1, arm.begin(), arm.end());
  for (const AccessRule& rule :
       topic_rules_of({"/**", std::nullopt, std::vector<AccessPrincipal>{}})) {
    rules.push_back(rule);
  }
  return source;
}

TEST(PolicyShow, ServicesRulesShowAsWrittenInPlace) {
  FakeSource source = policy_system_with_services();
  ASSERT_EQ(source.policy->rules.size(), 7u);
  EXPECT_EQ(policy_show_json(source), json::parse(R"({"policy": {"default": "allow", "rules": [
    {"topics": "/safety/**", "publish": ["group:safety"],
     "subscribe": ["group:agnocast", "user:monitor"]},
    {"services": "/arm/*", "serve": ["user:root"], "call": ["group:agnocast"]},
    {"topics": "/private/*", "publish": ["user:1234", "group:4321"], "subscribe": []},
    {"topics": "/open", "publish": null, "subscribe": ["*"]},
    {"services": "/**", "serve": null, "call": []}]}})"));
  EXPECT_EQ(policy_show_table(policy_show_json(source)),
            "default: allow (what no rule matches, and rights a rule leaves open)\n"
            "RULE               PUBLISH               SUBSCRIBE                    SERVE      "
            "CALL\n"
            "topics /safety/**  group:safety          group:agnocast,user:monitor\n"
            "services /arm/*                                                       user:root  "
            "group:agnocast\n"
            "topics /private/*  user:1234,group:4321  (nobody)\n"
            "topics /open       (default)             *\n"
            "services /**                                                          (default)  "
            "(nobody)\n");
}

TEST(PolicyShow, OnlyServicesRulesShowOnlyTheirRights) {
  FakeSource source = policy_system();
  source.policy->rules.clear();
  for (const AccessRule& rule : topic_rules_of({"/arm/enable", std::nullopt, std::nullopt})) {
    source.policy->rules.push_back(rule);
  }
  EXPECT_EQ(policy_show_table(policy_show_json(source)),
            "default: allow (what no rule matches, and rights a rule leaves open)\n"
            "RULE                  SERVE      CALL\n"
            "services /arm/enable  (default)  (default)\n");
}

TEST(PolicyShow, ARuleOnAServiceTopicThatNoServicesRuleMakesShowsAsATopicRule) {
  FakeSource source = policy_system();
  source.policy->rules = {{"/_service_request/arm/*", std::nullopt, std::nullopt}};
  EXPECT_EQ(policy_show_json(source)["policy"]["rules"],
            json::parse(R"([{"topics": "/_service_request/arm/*", "publish": null,
                             "subscribe": null}])"));
}

TEST(PolicyShow, ModuleAbsentThrowsModuleNotLoaded) {
  FakeSource source;
  source.loaded = false;
  EXPECT_THROW(policy_show_json(source), ModuleNotLoaded);
}

}  // namespace
}  // namespace agnocast::cli
