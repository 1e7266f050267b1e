// service list | info | type, and the services left out of the topic,
// queue and node views, built from fake system state.
#include <gtest/gtest.h>

#include "agnocast/errors.hpp"
#include "commands.hpp"
#include "fake_source.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

TopicInfo& topic_named(FakeSource& source, const std::string& name) {
  for (TopicInfo& topic : source.topics) {
    if (topic.name == name) return topic;
  }
  throw std::runtime_error("no topic " + name);
}

TEST(ServiceList, NameTypeServerAndClientCount) {
  FakeSource source = system_with_service();
  const json value = service_list_json(source);
  EXPECT_EQ(value, json::parse(R"({"services":[
      {"name":"/arm/enable","type":"std_srvs/srv/SetBool","server":400,"clients":3}]})"));
  EXPECT_EQ(service_list_table(value),
            "NAME         TYPE                  SERVER  CLIENTS\n"
            "/arm/enable  std_srvs/srv/SetBool     400        3\n");
}

TEST(ServiceList, SortedByNameWithoutServerAsDash) {
  FakeSource source = system_with_service();
  TopicInfo lonely;  // a client waiting for a server that is not there
  lonely.name = "/_service_request/calibrate";
  lonely.type_name = "example_interfaces/srv/AddTwoInts_Request";
  PublisherInfo call;
  call.id = 30;
  call.pid = 700;
  call.node = "tool";
  lonely.publishers.push_back(call);
  source.topics.push_back(lonely);
  const json value = service_list_json(source);
  EXPECT_EQ(value["services"][0],
            json::parse(R"({"name":"/arm/enable","type":"std_srvs/srv/SetBool","server":400,
                            "clients":3})"));
  EXPECT_EQ(value["services"][1],
            json::parse(R"({"name":"/calibrate","type":"example_interfaces/srv/AddTwoInts",
                            "server":null,"clients":1})"));
  EXPECT_EQ(service_list_table(value),
            "NAME         TYPE                               SERVER  CLIENTS\n"
            "/arm/enable  std_srvs/srv/SetBool                  400        3\n"
            "/calibrate   example_interfaces/srv/AddTwoInts       -        1\n");
}

TEST(ServiceList, EmptyWithoutServices) {
  FakeSource source = healthy_system();
  EXPECT_EQ(service_list_json(source), json::parse(R"({"services":[]})"));
  EXPECT_EQ(service_list_table(service_list_json(source)), "NAME  TYPE  SERVER  CLIENTS\n");
}

TEST(ServiceList, ModuleAbsentThrowsModuleNotLoaded) {
  FakeSource source = system_with_service();
  source.loaded = false;
  EXPECT_THROW(service_list_json(source), ModuleNotLoaded);
  EXPECT_THROW(service_info_json(source, "/arm/enable"), ModuleNotLoaded);
}

TEST(ServiceInfo, ServerClientsPairedPerNodeInIdOrderAndTheirCounts) {
  FakeSource source = system_with_service();
  const json value = service_info_json(source, "/arm/enable");
  EXPECT_EQ(value, json::parse(R"({
      "name":"/arm/enable","type":"std_srvs/srv/SetBool",
      "request_topic":"/_service_request/arm/enable","reply_topic":"/_service_reply/arm/enable",
      "server":{"pid":400,"node":"arm_driver","uid":1002,"request_subscriber_id":10},
      "clients":[
        {"pid":500,"node":"panel","uid":1003,"request_publisher_id":13,"reply_subscriber_id":12,
         "calls":5,"answered":5,"in_flight":0},
        {"pid":600,"node":"planner","uid":1003,"request_publisher_id":15,"reply_subscriber_id":14,
         "calls":8,"answered":5,"in_flight":3},
        {"pid":600,"node":"planner","uid":1003,"request_publisher_id":17,"reply_subscriber_id":16,
         "calls":1,"answered":0,"in_flight":1}],
      "calls":14,"answered":10,"in_flight":4,"failures":2})"));
}

TEST(ServiceInfo, TableGoldenText) {
  FakeSource source = system_with_service();
  EXPECT_EQ(service_info_table(service_info_json(source, "/arm/enable")),
            "service    /arm/enable\n"
            "type       std_srvs/srv/SetBool\n"
            "server     400 (node arm_driver)\n"
            "calls      14\n"
            "answered   10\n"
            "in_flight  4\n"
            "failures   2\n"
            "\n"
            "clients\n"
            "PID   UID  NODE     CALLS  ANSWERED  IN_FLIGHT\n"
            "500  1003  panel        5         5          0\n"
            "600  1003  planner      8         5          3\n"
            "600  1003  planner      1         0          1\n");
}

TEST(ServiceInfo, WithoutServerItsFieldsAreNull) {
  FakeSource source = system_with_service();
  topic_named(source, "/_service_request/arm/enable").subscribers.clear();
  topic_named(source, "/_service_reply/arm/enable").publishers.clear();
  const json value = service_info_json(source, "/arm/enable");
  EXPECT_TRUE(value["server"].is_null());
  EXPECT_TRUE(value["failures"].is_null());
  EXPECT_EQ(value["clients"].size(), 3u);
  const std::string table = service_info_table(value);
  EXPECT_NE(table.find("server     -\n"), std::string::npos) << table;
  EXPECT_NE(table.find("failures   -\n"), std::string::npos) << table;
  EXPECT_EQ(service_list_json(source)["services"][0]["server"], nullptr);
}

TEST(ServiceInfo, AHalfMadeClientHasNullForWhatItLacks) {
  FakeSource source = system_with_service();
  TopicInfo& request = topic_named(source, "/_service_request/arm/enable");
  // The newest client has its reply subscriber (16) but not yet its request publisher.
  request.publishers.erase(request.publishers.begin());  // id 17, of planner
  const json clients = service_info_json(source, "/arm/enable")["clients"];
  ASSERT_EQ(clients.size(), 3u);
  EXPECT_EQ(clients[2], json::parse(R"({"pid":600,"node":"planner","uid":1003,
      "request_publisher_id":null,"reply_subscriber_id":16,
      "calls":null,"answered":0,"in_flight":null})"));
  EXPECT_EQ(service_info_json(source, "/arm/enable")["calls"], 13);
  EXPECT_EQ(service_info_table(service_info_json(source, "/arm/enable"))
                    .find("600  1003  planner      -         0          -\n") != std::string::npos,
            true);
}

TEST(ServiceInfo, MoreAnswersThanCallsIsNoneInFlight) {
  FakeSource source = system_with_service();
  topic_named(source, "/_service_reply/arm/enable").subscribers[1].received = 100;  // panel
  EXPECT_EQ(service_info_json(source, "/arm/enable")["clients"][0]["in_flight"], 0);
}

TEST(ServiceInfo, TypeFromTheReplyTopicWhenAloneAndNullWhenNeitherHasTheForm) {
  FakeSource source = system_with_service();
  source.topics.erase(source.topics.end() - 2);  // the request topic
  json value = service_info_json(source, "/arm/enable");
  EXPECT_EQ(value["type"], "std_srvs/srv/SetBool");
  EXPECT_TRUE(value["server"].is_null());
  EXPECT_EQ(value["calls"], 0);
  EXPECT_EQ(value["clients"][0]["answered"], 5);
  topic_named(source, "/_service_reply/arm/enable").type_name = "custom/Thing";
  EXPECT_TRUE(service_info_json(source, "/arm/enable")["type"].is_null());
  EXPECT_EQ(service_type_table(service_type_json(source, "/arm/enable")), "-\n");
}

TEST(ServiceInfo, AnUnknownServiceIsARuntimeErrorNamingServiceList) {
  FakeSource source = system_with_service();
  for (const char* name : {"/nope", "/arm", "/enable"}) {
    try {
      service_info_json(source, name);
      FAIL() << "expected CliError for " << name;
    } catch (const CliError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + name + "'"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("service list"), std::string::npos);
    }
    EXPECT_THROW(service_type_json(source, name), CliError);
  }
}

TEST(ServiceType, TheServiceTypeNotTheRequestType) {
  FakeSource source = system_with_service();
  const json value = service_type_json(source, "/arm/enable");
  EXPECT_EQ(value, json::parse(R"({"name":"/arm/enable","type":"std_srvs/srv/SetBool"})"));
  EXPECT_EQ(service_type_table(value), "std_srvs/srv/SetBool\n");
}

TEST(ServiceType, OnlyTheSuffixOfItsOwnTopicIsStripped) {
  EXPECT_EQ(service_type_of("a/srv/B_Request", ServiceTopicRole::request), "a/srv/B");
  EXPECT_EQ(service_type_of("a/srv/B_Response", ServiceTopicRole::reply), "a/srv/B");
  EXPECT_EQ(service_type_of("a/srv/B_Response", ServiceTopicRole::request), "");
  EXPECT_EQ(service_type_of("a/srv/B_Request", ServiceTopicRole::reply), "");
  EXPECT_EQ(service_type_of("_Request", ServiceTopicRole::request), "");
  EXPECT_EQ(service_type_of("", ServiceTopicRole::request), "");
}

TEST(ServiceHiding, TopicListLeavesOutTheTopicsThatCarryServices) {
  FakeSource source = system_with_service();
  TopicInfo look_alike;  // an ordinary topic
  look_alike.name = "/_service_requests";
  source.topics.push_back(look_alike);
  EXPECT_EQ(topic_list_json(source), json::parse(R"({"topics":[
                {"name":"/_service_requests","type":null,"publishers":0,"subscribers":0},
                {"name":"/chatter","type":"chatter/msg/Message","publishers":1,
                 "subscribers":2}]})"));
}

TEST(ServiceHiding, QueueListLeavesOutLiveQueuesOfServices) {
  FakeSource source = system_with_service();
  // No live subscriber owns it: shown stale, whatever its name says.
  source.queues["/_service_reply_arm_enable@99"] = {0, 10};
  const json value = queue_list_json(source);
  ASSERT_EQ(value["queues"].size(), 2u) << value.dump();
  EXPECT_EQ(value["queues"][0]["name"], "/_service_reply_arm_enable@99");
  EXPECT_EQ(value["queues"][0]["stale"], true);
  EXPECT_EQ(value["queues"][1]["name"], "/chatter@1");
}

TEST(ServiceHiding, TopicInfoStillShowsACarrierGivenByName) {
  FakeSource source = system_with_service();
  const json value = topic_info_json(source, "/_service_request/arm/enable");
  EXPECT_EQ(value["type"], "std_srvs/srv/SetBool_Request");
  EXPECT_EQ(value["subscribers"][0]["queue"], "/_service_request_arm_enable@10");
}

TEST(ServiceHiding, NodesServeAndCallServicesInsteadOfUsingTheirTopics) {
  FakeSource source = system_with_service();
  const json nodes = node_list_json(source)["nodes"];
  ASSERT_EQ(nodes.size(), 6u);
  EXPECT_EQ(nodes[3], json::parse(R"({"name":"arm_driver","pid":400,"publishes":[],
      "subscribes":[],"serves":["/arm/enable"],"calls":[]})"));
  EXPECT_EQ(nodes[5], json::parse(R"({"name":"planner","pid":600,"publishes":[],
      "subscribes":[],"serves":[],"calls":["/arm/enable"]})"));
  EXPECT_EQ(node_list_table(node_list_json(source)),
            "NAME        PID  PUBLISHES  SUBSCRIBES  SERVES       CALLS\n"
            "talker      100  /chatter   -           -            -\n"
            "listener    200  -          /chatter    -            -\n"
            "poller      300  -          /chatter    -            -\n"
            "arm_driver  400  -          -           /arm/enable  -\n"
            "panel       500  -          -           -            /arm/enable\n"
            "planner     600  -          -           -            /arm/enable\n");
  const json server = node_info_json(source, "arm_driver");
  EXPECT_EQ(server, json::parse(R"({"name":"arm_driver","pids":[400],"publishers":[],
      "subscribers":[],"servers":[{"service":"/arm/enable","type":"std_srvs/srv/SetBool"}],
      "clients":[]})"));
  EXPECT_EQ(node_info_table(server),
            "node arm_driver\n"
            "pids 400\n"
            "\n"
            "DIRECTION  TOPIC  TYPE\n"
            "\n"
            "ROLE    SERVICE      TYPE\n"
            "serves  /arm/enable  std_srvs/srv/SetBool\n");
  EXPECT_EQ(node_info_json(source, "planner")["clients"],
            json::parse(R"([{"service":"/arm/enable","type":"std_srvs/srv/SetBool"}])"));
}

TEST(ServiceHiding, EchoAndRecordRefuseTheTopicsThatCarryServices) {
  EXPECT_EQ(service_topic_refusal("/_service_request/arm/enable"),
            "topic '/_service_request/arm/enable' carries the requests of service "
            "'/arm/enable'; `agnocast-cli service info /arm/enable` shows its server and clients");
  EXPECT_NE(service_topic_refusal("/_service_reply/x").find("the responses of service '/x'"),
            std::string::npos);
  EXPECT_EQ(service_topic_refusal("/chatter"), "");
  EXPECT_EQ(service_topic_refusal("/_service_replyx"), "");
}

}  // namespace
}  // namespace agnocast::cli
