// What executors need from a node: its subscriptions and timers, and a way to
// hear of new ones.
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
  explicit NodeState(std::string node_name)
      : name(std::move(node_name)),
        default_group(std::make_shared<CallbackGroup>(CallbackGroupType::MutuallyExclusive)) {}
  ~NodeState();  // its init events and its groups' are not sent again
  NodeState(const NodeState&) = delete;
  NodeState& operator=(const NodeState&) = delete;

  void add_waitable(const std::shared_ptr<Waitable>& waitable);
  void remove_waitable(std::uint64_t key);
  std::vector<std::weak_ptr<Waitable>> waitables_snapshot();
  // An executor's eventfd, written whenever the waitables change.
  void add_watcher(int eventfd);
  void remove_watcher(int eventfd);

  const std::string name;
  const std::shared_ptr<CallbackGroup> default_group;

 private:
  void notify_watchers();  // with mutex held

  std::mutex mutex;
  std::map<std::uint64_t, std::weak_ptr<Waitable>> waitables;
  std::vector<int> watchers;
};

}  // namespace agnocast::detail
