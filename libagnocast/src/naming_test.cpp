#include "agnocast/naming.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace agnocast {
namespace {

TEST(TopicName, AcceptsWellFormedNames) {
  for (const char* name : {"/chatter", "/a", "/sensing/lidar/points", "/A_z/0_9", "/_"}) {
    EXPECT_TRUE(is_valid_topic_name(name)) << name;
    EXPECT_NO_THROW(validate_topic_name(name)) << name;
  }
}

TEST(TopicName, RejectsEachRuleWithItsReason) {
  const struct {
    const char* name;
    const char* reason;
  } cases[] = {
      {"", "must start with '/'"},
      {"chatter", "must start with '/'"},
      {"/chat ter", "only A-Z a-z 0-9 _ and /"},
      {"/chat-ter", "only A-Z a-z 0-9 _ and /"},
      {"/caf\xc3\xa9", "only A-Z a-z 0-9 _ and /"},
      {"/a//b", "\"//\""},
      {"/a/", "must not end with '/'"},
      {"/", "after '/'"},
  };
  for (const auto& c : cases) {
    EXPECT_FALSE(is_valid_topic_name(c.name)) << c.name;
    try {
      validate_topic_name(c.name);
      ADD_FAILURE() << "accepted " << c.name;
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(c.reason), std::string::npos) << error.what();
    }
  }
}

TEST(TopicName, LengthLimitKeepsEveryQueueNameWithinNameMax) {
  const std::string longest = "/" + std::string(topic_name_max - 1, 'x');
  EXPECT_TRUE(is_valid_topic_name(longest));
  // mq_open's limit applies to the name after its leading '/'.
  EXPECT_LE(queue_name(longest, 4294967295U).size() - 1, queue_name_max);
  const std::string too_long = longest + "x";
  try {
    validate_topic_name(too_long);
    ADD_FAILURE();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("NAME_MAX (255)"), std::string::npos);
  }
}

TEST(QueueName, FollowsTheSeedExamples) {
  EXPECT_EQ(queue_name("/chatter", 3), "/chatter@3");
  EXPECT_EQ(queue_name("/sensing/lidar/points", 0), "/sensing_lidar_points@0");
  EXPECT_EQ(mangle_topic_name("/a/b"), "/a_b");
  EXPECT_EQ(queue_name("/a/b", 7), queue_name("/a_b", 7));  // why the kernel never reuses ids
}

TEST(QueueName, ParsesBothFormsBack) {
  auto parts = parse_queue_name("/sensing_lidar_points@12");
  ASSERT_TRUE(parts);
  EXPECT_EQ(parts->mangled_topic, "/sensing_lidar_points");
  EXPECT_EQ(parts->subscriber_id, 12U);
  parts = parse_queue_name("chatter@0");
  ASSERT_TRUE(parts);
  EXPECT_EQ(parts->mangled_topic, "/chatter");
  EXPECT_EQ(parts->subscriber_id, 0U);
  parts = parse_queue_name("x@4294967295");
  ASSERT_TRUE(parts);
  EXPECT_EQ(parts->subscriber_id, 4294967295U);
}

TEST(QueueName, RejectsForeignNames) {
  for (const char* name : {"chatter", "@1", "chatter@", "chatter@x", "chatter@-1", "chatter@01",
                           "chatter@4294967296", "chat-ter@1", "a/b@1", "chatter@1@2"}) {
    EXPECT_FALSE(parse_queue_name(name)) << name;
  }
}

}  // namespace
}  // namespace agnocast

TEST(ServiceName, TwoTopicsPerServiceAndBack) {
  EXPECT_EQ(agnocast::service_request_topic("/arm/enable"), "/_service_request/arm/enable");
  EXPECT_EQ(agnocast::service_reply_topic("/arm/enable"), "/_service_reply/arm/enable");
  const auto request = agnocast::service_of_topic("/_service_request/arm/enable");
  ASSERT_TRUE(request);
  EXPECT_EQ(request->service, "/arm/enable");
  EXPECT_EQ(request->role, agnocast::ServiceTopicRole::request);
  const auto reply = agnocast::service_of_topic("/_service_reply/x");
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->service, "/x");
  EXPECT_EQ(reply->role, agnocast::ServiceTopicRole::reply);
  // Only the whole first component is reserved.
  EXPECT_FALSE(agnocast::service_of_topic("/_service_requests/x"));
  EXPECT_FALSE(agnocast::service_of_topic("/_service_request"));
  EXPECT_FALSE(agnocast::service_of_topic("/chatter"));
  EXPECT_TRUE(agnocast::is_service_topic("/_service_request"));
  EXPECT_FALSE(agnocast::is_service_topic("/_service_replyx"));
}

TEST(ServiceName, FollowsTopicRulesWithRoomForThePrefix) {
  EXPECT_EQ(agnocast::service_name_problem("/add_two_ints"), "");
  EXPECT_NE(agnocast::service_name_problem("add").find("service name 'add' must start with '/'"),
            std::string::npos);
  EXPECT_NE(agnocast::service_name_problem("/_service_reply/a").find("must not start with"),
            std::string::npos);
  const std::string longest = "/" + std::string(agnocast::service_name_max - 1, 'a');
  EXPECT_EQ(agnocast::service_name_problem(longest), "");
  EXPECT_TRUE(agnocast::is_valid_topic_name(agnocast::service_request_topic(longest)));
  EXPECT_NE(agnocast::service_name_problem(longest + "a").find("too long"), std::string::npos);
  EXPECT_THROW(agnocast::validate_service_name("/a b"), std::invalid_argument);
}
