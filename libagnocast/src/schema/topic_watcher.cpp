#include "agnocast/topic_watcher.hpp"

#include <utility>

#include "agnocast/naming.hpp"

namespace agnocast {

bool TopicWatcher::counts(const TopicSummary& topic) const {
  if (topic.type_name.empty() || topic.type_name.starts_with("raw:")) return false;
  if (is_service_topic(topic.name)) return false;  // no application may subscribe there
  if (options_.wanted && !options_.wanted(topic.name)) return false;
  if (options_.publishers_only) return topic.publishers > 0;
  const std::uint32_t own = options_.own_endpoints ? options_.own_endpoints(topic.name) : 0;
  return topic.publishers + topic.subscribers > own;
}

TopicChanges TopicWatcher::poll() {
  TopicChanges changes;
  std::map<std::string, std::pair<std::string, std::uint64_t>> now;
  for (const TopicSummary& topic : options_.list()) {
    if (!counts(topic)) continue;
    const std::pair<std::string, std::uint64_t> type{topic.type_name, topic.type_hash};
    const auto known = present_.find(topic.name);
    if (known != present_.end() && known->second == type) {
      now.emplace(topic.name, type);
      continue;
    }
    if (refused_.contains({topic.name, topic.type_hash})) continue;
    try {
      std::optional<SchemaTopic> found = options_.resolve(topic.name);
      if (!found || found->type_hash != topic.type_hash) continue;  // changed meanwhile
      std::string definition = found->definition();
      changes.appeared.push_back({std::move(*found), std::move(definition)});
      now.emplace(topic.name, type);
    } catch (const std::exception& error) {
      refused_.insert({topic.name, topic.type_hash});
      changes.refused.push_back({topic.name, topic.type_name, error.what()});
    }
  }
  for (const auto& [name, type] : present_) {
    const auto still = now.find(name);
    if (still == now.end() || still->second != type) changes.gone.push_back(name);
  }
  present_ = std::move(now);
  return changes;
}

}  // namespace agnocast
