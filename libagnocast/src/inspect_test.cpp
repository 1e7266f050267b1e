#include "agnocast/inspect.hpp"

#include <gtest/gtest.h>

#include <string>

#include "agnocast/errors.hpp"
#include "agnocast/supervise.hpp"

namespace agnocast {
namespace {

// Natively there is no module: every entry point must say so the same way.
class WithoutModule : public ::testing::Test {
 protected:
  void SetUp() override {
    if (module_loaded()) GTEST_SKIP() << "/dev/agnocast exists here";
  }
};

TEST_F(WithoutModule, VersionIsAbsent) { EXPECT_FALSE(module_version()); }

TEST_F(WithoutModule, QueriesThrowModuleNotLoadedWithAdvice) {
  try {
    list_topics();
    ADD_FAILURE() << "list_topics worked without a module";
  } catch (const ModuleNotLoaded& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/dev/agnocast"), std::string::npos) << message;
    EXPECT_NE(message.find("systemctl start agnocastd"), std::string::npos) << message;
  }
  EXPECT_THROW(topic_info("/chatter"), ModuleNotLoaded);
  EXPECT_THROW(list_processes(), ModuleNotLoaded);
  EXPECT_THROW(ExitRecordReader{}, ModuleNotLoaded);
  EXPECT_THROW(live_queue_owners(), ModuleNotLoaded);
}

SubscriberInfo subscriber(std::uint32_t id, pid_t pid, bool polling = false) {
  SubscriberInfo info;
  info.id = id;
  info.pid = pid;
  info.polling = polling;
  return info;
}

TEST(QueueOwners, EveryCallbackSubscriberOwnsItsQueueAndPollingOnesNone) {
  TopicInfo chatter;
  chatter.name = "/a/chatter";
  chatter.subscribers = {subscriber(1, 10), subscriber(2, 20, /*polling=*/true)};
  TopicInfo status;
  status.name = "/status";
  status.subscribers = {subscriber(7, 30)};
  const std::map<std::string, QueueOwner> owners = queue_owners({chatter, status, TopicInfo{}});
  ASSERT_EQ(owners.size(), 2u);
  EXPECT_EQ(owners.at("/a_chatter@1").topic, "/a/chatter");
  EXPECT_EQ(owners.at("/a_chatter@1").subscriber_id, 1u);
  EXPECT_EQ(owners.at("/a_chatter@1").pid, 10);
  EXPECT_EQ(owners.at("/status@7").topic, "/status");
  EXPECT_EQ(owners.at("/status@7").pid, 30);
}

TEST(LibraryVersion, IsTheProjectVersionAndCompatibilityIsMajorMinor) {
  EXPECT_EQ(library_version.to_string(), std::string(library_version_string));
  EXPECT_TRUE(is_compatible({library_version.major, library_version.minor, 99}));
  EXPECT_FALSE(is_compatible({library_version.major, library_version.minor + 1, 0}));
  EXPECT_FALSE(is_compatible({library_version.major + 1, library_version.minor, 0}));
}

}  // namespace
}  // namespace agnocast
