// Typed topics as they appear, change type and go away: what a tool that
// follows every topic (bag record --all, agnocast-foxglove) polls, so that each
// applies the same rules and gives a topic the same definition.
//
//   TopicWatcher watcher({.publishers_only = true});
//   for (;;) {
//     const TopicChanges changes = watcher.poll();
//     for (const std::string& name : changes.gone) ...          // first
//     for (const WatchedTopic& topic : changes.appeared) ...    // then
//     for (const RefusedTopic& topic : changes.refused) ...     // once each
//   }
//
// A topic is present while it has a message type with a schema (not "raw:")
// and more endpoints than the caller's own (own_endpoints), or a publisher
// when publishers_only; the topics that carry services never are. One that changes type is gone and
// appears again in the same poll. One whose schema cannot be used is refused once per type.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "agnocast/inspect.hpp"
#include "agnocast/schema_topic.hpp"

namespace agnocast {

struct WatchedTopic {
  SchemaTopic topic;
  // The type's full .msg text, as rosbag2 writes it (SchemaTopic::definition()).
  std::string definition;
};

struct RefusedTopic {
  std::string name;
  std::string type_name;
  std::string problem;
};

struct TopicChanges {
  std::vector<std::string> gone;
  std::vector<WatchedTopic> appeared;
  std::vector<RefusedTopic> refused;
};

struct TopicWatcherOptions {
  // Only topics this says yes to (all when unset).
  std::function<bool(const std::string& name)> wanted;
  // Endpoints the caller itself has on the topic, which do not make it present.
  std::function<std::uint32_t(const std::string& name)> own_endpoints;
  // Present only with a publisher (a recorder has nothing to record otherwise).
  bool publishers_only = false;
  // Where topics come from: the kernel unless a test says otherwise.
  std::function<std::vector<TopicSummary>()> list = [] { return list_topics(); };
  std::function<std::optional<SchemaTopic>(const std::string& name)> resolve =
      [](const std::string& name) { return find_schema_topic(name); };
};

class TopicWatcher {
 public:
  explicit TopicWatcher(TopicWatcherOptions options) : options_(std::move(options)) {}

  // What changed since the last poll (everything present, the first time).
  TopicChanges poll();

  // The topics present now, by name: their type name and hash.
  const std::map<std::string, std::pair<std::string, std::uint64_t>>& present() const {
    return present_;
  }

 private:
  bool counts(const TopicSummary& topic) const;

  TopicWatcherOptions options_;
  std::map<std::string, std::pair<std::string, std::uint64_t>> present_;
  std::set<std::pair<std::string, std::uint64_t>> refused_;  // topic and type hash
};

}  // namespace agnocast
