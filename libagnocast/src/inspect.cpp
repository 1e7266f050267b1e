#include "agnocast/inspect.hpp"

#include <unistd.h>

#include <utility>

#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"
#include "kernel/device.hpp"

namespace agnocast {

std::map<std::string, QueueOwner> queue_owners(const std::vector<TopicInfo>& topics) {
  std::map<std::string, QueueOwner> owners;
  for (const TopicInfo& topic : topics) {
    for (const SubscriberInfo& subscriber : topic.subscribers) {
      if (subscriber.polling) continue;
      owners.emplace(queue_name(topic.name, subscriber.id),
                     QueueOwner{topic.name, subscriber.id, subscriber.pid});
    }
  }
  return owners;
}

bool module_loaded() { return ::access(device_path, F_OK) == 0; }

std::optional<Version> module_version() {
  try {
    return detail::Device::open().get_version();
  } catch (const ModuleNotLoaded&) {
    return std::nullopt;
  }
}

std::vector<TopicSummary> list_topics() { return detail::Device::open().list_topics(); }

std::optional<TopicInfo> topic_info(const std::string& topic) {
  TopicInfo info;
  if (!detail::Device::open().topic_info(topic, info)) return std::nullopt;
  return info;
}

std::vector<ProcessInfo> list_processes() { return detail::Device::open().list_processes(); }

std::optional<std::vector<std::uint8_t>> topic_schema(const std::string& topic) {
  return detail::Device::open().topic_schema(topic);
}

std::map<std::string, QueueOwner> live_queue_owners() {
  std::vector<TopicInfo> topics;
  for (const TopicSummary& summary : list_topics()) {
    // nullopt: its last endpoint left since list_topics.
    if (std::optional<TopicInfo> info = topic_info(summary.name))
      topics.push_back(std::move(*info));
  }
  return queue_owners(topics);
}

}  // namespace agnocast
