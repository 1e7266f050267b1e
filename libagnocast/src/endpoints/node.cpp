#include "agnocast/node.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <stdexcept>

#include "agnocast/limits.hpp"
#include "endpoints/node_state.hpp"
#include "tracing/trace.hpp"

namespace agnocast {
namespace {

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
  AGNOCAST_TRACE_INIT(state_.get(), [node = state_.get(), name = state_->name.c_str()] {
    AGNOCAST_TRACE(agnocast_node_init, node, name);
  });
  AGNOCAST_TRACE_INIT(state_.get(), [node = state_.get(), group = state_->default_group.get()] {
    AGNOCAST_TRACE(agnocast_callback_group_init, group, node, "mutually_exclusive");
  });
}

Node::~Node() = default;

const std::string& Node::get_name() const { return state_->name; }

std::shared_ptr<CallbackGroup> Node::create_callback_group(CallbackGroupType type) {
  auto group = std::make_shared<CallbackGroup>(type);
  // Kept as long as the node: a group is announced while its node lives.
  AGNOCAST_TRACE_INIT(
      state_.get(),
      [node = state_.get(), group = group.get(),
       kind = type == CallbackGroupType::Reentrant ? "reentrant" : "mutually_exclusive"] {
        AGNOCAST_TRACE(agnocast_callback_group_init, group, node, kind);
      });
  return group;
}

const std::shared_ptr<CallbackGroup>& Node::get_default_callback_group() const {
  return state_->default_group;
}

std::shared_ptr<Timer> Node::create_timer(std::chrono::nanoseconds period,
                                          std::function<void()> callback,
                                          std::shared_ptr<CallbackGroup> group) {
  auto timer = std::make_shared<Timer>(period, std::move(callback),
                                       detail::group_or_default(*state_, std::move(group)));
  AGNOCAST_TRACE_INIT(timer.get(),
                      [timer = timer.get(), node = state_.get(), group = timer->group().get(),
                       period = static_cast<std::int64_t>(period.count())] {
                        AGNOCAST_TRACE(agnocast_timer_init, timer, node, group, period);
                      });
  detail::register_waitable(*state_, timer);
  return timer;
}

namespace detail {

NodeState::~NodeState() { AGNOCAST_FORGET_INIT(this); }

void NodeState::add_waitable(const std::shared_ptr<Waitable>& waitable) {
  std::lock_guard lock(mutex);
  std::erase_if(waitables, [](const auto& entry) { return entry.second.expired(); });
  waitables[waitable->key()] = waitable;
  notify_watchers();
}

void NodeState::remove_waitable(std::uint64_t key) {
  std::lock_guard lock(mutex);
  waitables.erase(key);
}

std::vector<std::weak_ptr<Waitable>> NodeState::waitables_snapshot() {
  std::lock_guard lock(mutex);
  std::vector<std::weak_ptr<Waitable>> snapshot;
  for (const auto& [key, waitable] : waitables) snapshot.push_back(waitable);
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

std::shared_ptr<CallbackGroup> group_or_default(const NodeState& node,
                                                std::shared_ptr<CallbackGroup> requested) {
  return requested ? std::move(requested) : node.default_group;
}

void register_waitable(NodeState& node, const std::shared_ptr<Waitable>& waitable) {
  node.add_waitable(waitable);
}

namespace {
std::atomic<std::uint64_t> next_waitable_key{1};
}  // namespace

Waitable::Waitable(std::shared_ptr<CallbackGroup> group)
    : key_(next_waitable_key.fetch_add(1)), group_(std::move(group)) {}

Waitable::~Waitable() = default;

}  // namespace detail
}  // namespace agnocast
