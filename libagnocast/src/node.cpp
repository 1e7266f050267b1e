#include "agnocast/node.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include "node_state.hpp"

namespace agnocast {
namespace {

constexpr std::size_t node_name_max = 127;  // the module's label size less its NUL

void validate_node_name(const std::string& name) {
  if (name.size() > node_name_max) {
    throw std::invalid_argument("node name '" + name + "' is too long: at most " +
                                std::to_string(node_name_max) + " characters");
  }
  if (!std::all_of(name.begin(), name.end(), [](char c) { return c >= 0x20 && c < 0x7f; })) {
    throw std::invalid_argument("node name '" + name + "' may contain only printable ASCII");
  }
}

}  // namespace

Node::Node(std::string name) {
  validate_node_name(name);
  state_ = std::make_shared<detail::NodeState>(std::move(name));
}

Node::~Node() = default;

const std::string& Node::get_name() const { return state_->name; }

namespace detail {

void NodeState::add_subscription(const std::shared_ptr<SubscriptionBase>& subscription) {
  std::lock_guard lock(mutex);
  subscriptions[subscription->key()] = subscription;
  notify_watchers();
}

void NodeState::remove_subscription(std::uint64_t key) {
  std::lock_guard lock(mutex);
  subscriptions.erase(key);
}

std::vector<std::weak_ptr<SubscriptionBase>> NodeState::subscriptions_snapshot() {
  std::lock_guard lock(mutex);
  std::vector<std::weak_ptr<SubscriptionBase>> snapshot;
  for (const auto& [key, subscription] : subscriptions) snapshot.push_back(subscription);
  return snapshot;
}

void NodeState::add_watcher(int eventfd) {
  std::lock_guard lock(mutex);
  watchers.push_back(eventfd);
}

void NodeState::remove_watcher(int eventfd) {
  std::lock_guard lock(mutex);
  std::erase(watchers, eventfd);
}

void NodeState::notify_watchers() {
  const std::uint64_t one = 1;
  for (int fd : watchers) {
    [[maybe_unused]] const ssize_t written = ::write(fd, &one, sizeof one);
  }
}

void register_subscription(NodeState& node, const std::shared_ptr<SubscriptionBase>& subscription) {
  node.add_subscription(subscription);
}

}  // namespace detail
}  // namespace agnocast
