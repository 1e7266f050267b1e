#include "agnocast/topic_watcher.hpp"

#include <gtest/gtest.h>

#include <string_view>

namespace topic_watcher_test {

struct Reading {
  double value;
};
struct Sample {
  std::uint32_t id;
};

}  // namespace topic_watcher_test

AGNOCAST_MESSAGE(topic_watcher_test::Reading, "topic_watcher_test/msg/Reading", value);
AGNOCAST_MESSAGE(topic_watcher_test::Sample, "topic_watcher_test/msg/Sample", id);

namespace agnocast {
namespace {

using topic_watcher_test::Reading;

// A kernel's topic list the test edits between polls.
class Topics {
 public:
  template <class T>
  void add(const std::string& name, std::uint32_t publishers, std::uint32_t subscribers) {
    TopicSummary summary{name, publishers, subscribers, std::string(message_traits<T>::type_name),
                         message_traits<T>::type_hash};
    const auto blob = schema_of<T>();
    topics_[name] = {summary, std::vector<std::uint8_t>(blob.begin(), blob.end())};
  }
  void add_raw(const std::string& name) {
    topics_[name] = {TopicSummary{name, 1, 0, "raw:opaque", 7}, {}};
  }
  void remove(const std::string& name) { topics_.erase(name); }

  TopicWatcherOptions options() {
    TopicWatcherOptions options;
    options.list = [this] {
      std::vector<TopicSummary> list;
      for (const auto& [name, topic] : topics_) list.push_back(topic.first);
      return list;
    };
    options.resolve = [this](const std::string& name) -> std::optional<SchemaTopic> {
      const auto found = topics_.find(name);
      if (found == topics_.end()) return std::nullopt;
      SchemaTopic topic;
      topic.topic = name;
      topic.type_name = found->second.first.type_name;
      topic.type_hash = found->second.first.type_hash;
      topic.blob = found->second.second;
      topic.schema = parse_schema(topic.blob);
      return topic;
    };
    return options;
  }

 private:
  std::map<std::string, std::pair<TopicSummary, std::vector<std::uint8_t>>> topics_;
};

std::vector<std::string> names(const std::vector<WatchedTopic>& topics) {
  std::vector<std::string> out;
  for (const WatchedTopic& topic : topics) out.push_back(topic.topic.topic);
  return out;
}

TEST(TopicWatcher, ReportsTopicsAppearingChangingTypeAndGoingAway) {
  Topics topics;
  topics.add<Reading>("/a", 1, 0);
  topics.add<topic_watcher_test::Sample>("/b", 0, 1);
  topics.add_raw("/raw");
  TopicWatcher watcher(topics.options());

  TopicChanges changes = watcher.poll();
  EXPECT_EQ(names(changes.appeared), (std::vector<std::string>{"/a", "/b"}));
  EXPECT_TRUE(changes.gone.empty());
  EXPECT_EQ(changes.appeared[0].definition, "float64 value\n");
  EXPECT_EQ(changes.appeared[0].topic.type_name, "topic_watcher_test/msg/Reading");

  changes = watcher.poll();  // nothing changed, nothing reported
  EXPECT_TRUE(changes.appeared.empty() && changes.gone.empty() && changes.refused.empty());

  topics.add<topic_watcher_test::Sample>("/a", 1, 0);  // another type under the same name
  topics.remove("/b");
  changes = watcher.poll();
  EXPECT_EQ(changes.gone, (std::vector<std::string>{"/a", "/b"}));
  ASSERT_EQ(names(changes.appeared), (std::vector<std::string>{"/a"}));
  EXPECT_EQ(changes.appeared[0].topic.type_name, "topic_watcher_test/msg/Sample");
  EXPECT_EQ(watcher.present().size(), 1u);
}

TEST(TopicWatcher, CountsOnlyOthersEndpointsOrPublishers) {
  Topics topics;
  topics.add<Reading>("/mine", 0, 1);
  topics.add<Reading>("/listened", 0, 1);
  TopicWatcherOptions options = topics.options();
  options.own_endpoints = [](const std::string& name) { return name == "/mine" ? 1u : 0u; };
  TopicWatcher watcher(options);
  EXPECT_EQ(names(watcher.poll().appeared), (std::vector<std::string>{"/listened"}));

  options.publishers_only = true;
  TopicWatcher recorder(options);
  EXPECT_TRUE(recorder.poll().appeared.empty());
  topics.add<Reading>("/listened", 1, 1);
  EXPECT_EQ(names(recorder.poll().appeared), (std::vector<std::string>{"/listened"}));
}

TEST(TopicWatcher, UsesTheTypesOwnTextAndRefusesWhatHasNoDefinitionOnce) {
  Topics topics;
  topics.add<Reading>("/a", 1, 0);
  TopicWatcherOptions options = topics.options();
  // As agnocast-msggen's schema carries it (a type declared in C++ has none).
  const std::string text = "# a comment\nfloat64 value\nuint8 MODE_FAST=1\n";
  int resolved = 0;
  const auto resolve = options.resolve;
  options.resolve = [&](const std::string& name) {
    ++resolved;
    std::optional<SchemaTopic> topic = resolve(name);
    if (name == "/broken") throw SchemaError("schema: bad magic");
    if (topic) topic->schema.types[0].definition = text;
    return topic;
  };
  TopicWatcher watcher(options);
  topics.add<topic_watcher_test::Sample>("/broken", 1, 0);
  TopicChanges changes = watcher.poll();
  ASSERT_EQ(changes.appeared.size(), 1u);
  EXPECT_EQ(changes.appeared[0].definition, text);
  ASSERT_EQ(changes.refused.size(), 1u);
  EXPECT_EQ(changes.refused[0].name, "/broken");
  EXPECT_EQ(changes.refused[0].problem, "schema: bad magic");
  const int before = resolved;
  changes = watcher.poll();
  EXPECT_TRUE(changes.refused.empty());  // refused once per type
  EXPECT_EQ(resolved, before);
}

TEST(TopicWatcher, LeavesOutTheTopicsThatCarryServices) {
  Topics topics;
  topics.add<Reading>("/_service_request/calibrate", 1, 1);
  topics.add<topic_watcher_test::Sample>("/_service_reply/calibrate", 1, 1);
  topics.add<Reading>("/_service_requests", 1, 0);  // an ordinary topic
  TopicWatcher watcher(topics.options());
  const TopicChanges changes = watcher.poll();
  EXPECT_EQ(names(changes.appeared), std::vector<std::string>{"/_service_requests"});
  EXPECT_TRUE(changes.refused.empty());
}

}  // namespace
}  // namespace agnocast
