// What executors need from a node: its subscriptions and a way to hear of new ones.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "agnocast/detail/endpoints.hpp"

namespace agnocast::detail {

struct NodeState {
  explicit NodeState(std::string node_name) : name(std::move(node_name)) {}

  void add_subscription(const std::shared_ptr<SubscriptionBase>& subscription);
  void remove_subscription(std::uint64_t key);
  std::vector<std::weak_ptr<SubscriptionBase>> subscriptions_snapshot();
  // An executor's eventfd, written whenever the subscriptions change.
  void add_watcher(int eventfd);
  void remove_watcher(int eventfd);

  const std::string name;

 private:
  void notify_watchers();  // with mutex held

  std::mutex mutex;
  std::map<std::uint64_t, std::weak_ptr<SubscriptionBase>> subscriptions;
  std::vector<int> watchers;
};

}  // namespace agnocast::detail
