#include "kernel/fake_kernel.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <set>

#include "agnocast/errors.hpp"

namespace agnocast::detail {
namespace {

[[noreturn]] void fail(const char* command, int err) {
  throw DeviceError(err, std::string("fake kernel: ") + command + " failed");
}

}  // namespace

FakeKernel::FakeKernel() : caller_pid_(::getpid()) {}

FakeKernel::~FakeKernel() {
  for (const auto& [pid, fd] : wake_fds_) ::close(fd);
}

int FakeKernel::wake_fd() const {
  std::lock_guard lock(mutex_);
  auto found = wake_fds_.find(caller_pid_);
  if (found == wake_fds_.end()) {
    const int fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (fd < 0) fail("eventfd", errno);
    found = wake_fds_.emplace(caller_pid_, fd).first;
  }
  return found->second;
}

void FakeKernel::promise(Subscriber& subscriber) {
  if (!subscriber.notified) {
    subscriber.notified = true;
    subscriber.notified_at = std::chrono::steady_clock::now();
    subscriber.watchdog_fired = false;
  }
  subscriber.notifier = caller_pid_;
}

void FakeKernel::signal_wake(pid_t pid) {
  if (const auto found = wake_fds_.find(pid); found != wake_fds_.end()) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t written = ::write(found->second, &one, sizeof one);
  }
}

void FakeKernel::break_promise(Subscriber& subscriber) {
  subscriber.notified = false;
  signal_wake(subscriber.pid);
}

void FakeKernel::break_overdue_promises() {
  const auto now = std::chrono::steady_clock::now();
  for (auto& [handle, topic] : topics_) {
    for (auto& [id, subscriber] : topic.subscribers) {
      if (subscriber.notified && !subscriber.watchdog_fired &&
          now - subscriber.notified_at >= watchdog_period) {
        // Signals once per listing and lists nothing again, as the module's watchdog.
        subscriber.watchdog_fired = true;
        signal_wake(subscriber.pid);
      }
    }
  }
}

void FakeKernel::run_watchdog() {
  std::lock_guard lock(mutex_);
  break_overdue_promises();
}

void FakeKernel::notify_failed(EndpointId publisher, std::uint32_t subscriber_id) noexcept {
  std::lock_guard lock(mutex_);
  break_overdue_promises();
  const auto topic = topics_.find(publisher.topic_handle);
  if (topic == topics_.end()) return;
  const auto pub = topic->second.publishers.find(publisher.id);
  if (pub == topic->second.publishers.end() || pub->second.pid != caller_pid_) return;
  const auto sub = topic->second.subscribers.find(subscriber_id);
  // One that looked since got the entries.
  if (sub != topic->second.subscribers.end() && sub->second.notified) break_promise(sub->second);
}

void FakeKernel::end_process(pid_t pid) {
  std::lock_guard lock(mutex_);
  for (auto& [handle, topic] : topics_) {
    const bool published = std::any_of(topic.publishers.begin(), topic.publishers.end(),
                                       [&](const auto& entry) { return entry.second.pid == pid; });
    if (!published) continue;
    for (auto& [id, subscriber] : topic.subscribers) {
      if (subscriber.notified && subscriber.notifier == pid) break_promise(subscriber);
    }
  }
  for (auto& [handle, topic] : topics_) {
    std::vector<std::uint32_t> subscribers, publishers;
    for (const auto& [id, subscriber] : topic.subscribers) {
      if (subscriber.pid == pid) subscribers.push_back(id);
    }
    for (const auto& [id, publisher] : topic.publishers) {
      if (publisher.pid == pid) publishers.push_back(id);
    }
    for (const std::uint32_t id : subscribers) remove_subscriber_locked(topic, id);
    for (const std::uint32_t id : publishers) remove_publisher_locked(topic, id);
  }
  reclaimable_.erase(pid);
  if (const auto found = wake_fds_.find(pid); found != wake_fds_.end()) {
    ::close(found->second);
    wake_fds_.erase(found);
  }
}

std::uint32_t FakeKernel::join(const EndpointRequest& request) {
  for (const auto& [handle, topic] : topics_) {
    if (topic.name != request.topic) continue;
    if (topic.type_name != request.type_name || topic.type_hash != request.type_hash) {
      throw TypeMismatch("fake kernel: topic " + request.topic + " carries " + topic.type_name);
    }
    return handle;
  }
  const std::uint32_t handle = next_handle_++;
  Topic& topic = topics_[handle];
  topic.name = request.topic;
  topic.type_name = request.type_name;
  topic.type_hash = request.type_hash;
  return handle;
}

FakeKernel::Topic& FakeKernel::topic_of(EndpointId endpoint) {
  const auto found = topics_.find(endpoint.topic_handle);
  if (found == topics_.end()) fail("topic lookup", ENOENT);
  return found->second;
}

FakeKernel::Subscriber& FakeKernel::subscriber_of(EndpointId endpoint) {
  Topic& topic = topic_of(endpoint);
  const auto found = topic.subscribers.find(endpoint.id);
  if (found == topic.subscribers.end()) fail("subscriber lookup", ENOENT);
  if (found->second.pid != caller_pid_) fail("subscriber lookup", EPERM);
  return found->second;
}

EndpointId FakeKernel::add_publisher(const EndpointRequest& request) {
  std::lock_guard lock(mutex_);
  if (request.polling || request.ignore_local || request.wake_once) fail("ADD_PUBLISHER", EINVAL);
  const std::uint32_t handle = join(request);
  Topic& topic = topics_[handle];
  const std::uint32_t id = next_id_++;
  Publisher& publisher = topic.publishers[id];
  publisher.node = request.node;
  publisher.pid = caller_pid_;
  publisher.depth = request.depth;
  publisher.transient_local = request.transient_local;
  return EndpointId{handle, id};
}

EndpointId FakeKernel::add_subscriber(const EndpointRequest& request) {
  std::lock_guard lock(mutex_);
  if (request.polling && request.wake_once) fail("ADD_SUBSCRIBER", EINVAL);
  const std::uint32_t handle = join(request);
  Topic& topic = topics_[handle];
  const std::uint32_t id = next_id_++;
  Subscriber& subscriber = topic.subscribers[id];
  subscriber.node = request.node;
  subscriber.pid = caller_pid_;
  subscriber.depth = request.depth;
  subscriber.transient_local = request.transient_local;
  subscriber.polling = request.polling;
  subscriber.ignore_local = request.ignore_local;
  subscriber.wake_once = request.wake_once;
  if (request.transient_local) {
    std::vector<std::uint64_t> kept;
    for (const auto& [publisher_id, publisher] : topic.publishers) {
      if (!publisher.transient_local) continue;
      if (subscriber.ignore_local && publisher.pid == caller_pid_) continue;
      kept.insert(kept.end(), publisher.window.begin(), publisher.window.end());
    }
    std::sort(kept.begin(), kept.end());
    const std::size_t skip = kept.size() > request.depth ? kept.size() - request.depth : 0;
    for (std::size_t i = skip; i < kept.size(); ++i) {
      subscriber.unreceived.push_back(kept[i]);
      ++entries_[kept[i]].unreceived_by;
    }
  }
  return EndpointId{handle, id};
}

void FakeKernel::remove_publisher(EndpointId endpoint) {
  std::lock_guard lock(mutex_);
  Topic& topic = topic_of(endpoint);
  if (!topic.publishers.contains(endpoint.id)) fail("REMOVE_PUBLISHER", ENOENT);
  remove_publisher_locked(topic, endpoint.id);
}

void FakeKernel::remove_publisher_locked(Topic& topic, std::uint32_t id) {
  const auto found = topic.publishers.find(id);
  const std::deque<std::uint64_t> window = std::move(found->second.window);
  topic.publishers.erase(found);
  for (std::uint64_t entry_id : window) {
    entries_[entry_id].in_window = false;
    settle(entry_id);
  }
}

void FakeKernel::remove_subscriber(EndpointId endpoint) {
  std::lock_guard lock(mutex_);
  subscriber_of(endpoint);  // checks that it is the caller's
  remove_subscriber_locked(topic_of(endpoint), endpoint.id);
}

void FakeKernel::remove_subscriber_locked(Topic& topic, std::uint32_t id) {
  Subscriber& subscriber = topic.subscribers.at(id);
  const std::deque<std::uint64_t> unreceived = std::move(subscriber.unreceived);
  const std::multiset<std::uint64_t> held = std::move(subscriber.held);
  topic.subscribers.erase(id);
  for (std::uint64_t entry_id : unreceived) {
    --entries_[entry_id].unreceived_by;
    settle(entry_id);
  }
  for (std::uint64_t entry_id : held) {
    --entries_[entry_id].held_by;
    settle(entry_id);
  }
}

void FakeKernel::settle(std::uint64_t entry_id) {
  const auto found = entries_.find(entry_id);
  const Entry& entry = found->second;
  if (entry.in_window || entry.unreceived_by > 0 || entry.held_by > 0) return;
  reclaimable_[entry.pid].push_back(entry.addr);
  entries_.erase(found);
}

void FakeKernel::drop_unreceived(Subscriber& subscriber, std::uint64_t entry_id) {
  --entries_[entry_id].unreceived_by;
  ++subscriber.dropped;
  settle(entry_id);
}

PublishResult FakeKernel::publish(EndpointId publisher_id, std::uint64_t addr, std::uint64_t bytes,
                                  std::span<std::uint32_t> wake_ids,
                                  std::span<std::uint64_t> reclaim, const ServiceRoute& route) {
  std::lock_guard lock(mutex_);
  break_overdue_promises();
  ++calls_.publish;
  Topic& topic = topic_of(publisher_id);
  const auto found = topic.publishers.find(publisher_id.id);
  if (found == topic.publishers.end()) fail("PUBLISH", ENOENT);
  if (found->second.pid != caller_pid_) fail("PUBLISH", EPERM);
  Publisher& publisher = found->second;
  // Room for every callback subscriber, as the module asks: polling ones are never woken.
  const auto callback_subscribers =
      std::count_if(topic.subscribers.begin(), topic.subscribers.end(),
                    [](const auto& entry) { return !entry.second.polling; });
  const auto receives = [&](std::uint32_t id, const Subscriber& subscriber) {
    if (subscriber.ignore_local && subscriber.pid == caller_pid_) return false;
    return !route.to_subscriber || *route.to_subscriber == id;
  };
  if (route.to_subscriber) {
    if (publisher.transient_local) fail("PUBLISH", EINVAL);
    const auto to = topic.subscribers.find(*route.to_subscriber);
    if (to == topic.subscribers.end() || !receives(to->first, to->second)) fail("PUBLISH", ENXIO);
    if (wake_ids.empty()) fail("PUBLISH", ENOBUFS);
  } else if (wake_ids.size() < static_cast<std::size_t>(callback_subscribers)) {
    fail("PUBLISH", ENOBUFS);
  }
  if (route.no_drop) {
    bool any = false;
    for (const auto& [id, subscriber] : topic.subscribers) {
      if (!receives(id, subscriber)) continue;
      if (subscriber.unreceived.size() >= subscriber.depth) fail("PUBLISH", EAGAIN);
      any = true;
    }
    if (!any) fail("PUBLISH", EPIPE);
  }

  const std::uint64_t entry_id = next_entry_id_++;
  entries_[entry_id] =
      Entry{addr, publisher_id.topic_handle, publisher_id.id, caller_pid_, true, 0, 0};
  ++publisher.published;
  publisher.published_bytes += bytes;
  PublishResult result;
  result.entry_id = entry_id;
  for (auto& [id, subscriber] : topic.subscribers) {
    if (!receives(id, subscriber)) continue;
    subscriber.unreceived.push_back(entry_id);
    ++entries_[entry_id].unreceived_by;
    if (subscriber.unreceived.size() > subscriber.depth) {
      const std::uint64_t oldest = subscriber.unreceived.front();
      subscriber.unreceived.pop_front();
      drop_unreceived(subscriber, oldest);
    }
    if (subscriber.polling || (subscriber.wake_once && subscriber.notified)) continue;
    promise(subscriber);
    wake_ids[result.wake_count++] = id;
  }
  publisher.window.push_back(entry_id);
  if (publisher.window.size() > publisher.depth) {
    const std::uint64_t oldest = publisher.window.front();
    publisher.window.pop_front();
    entries_[oldest].in_window = false;
    settle(oldest);
  }
  std::deque<std::uint64_t>& freeable = reclaimable_[caller_pid_];
  while (result.reclaim_count < reclaim.size() && !freeable.empty()) {
    reclaim[result.reclaim_count++] = freeable.front();
    freeable.pop_front();
  }
  result.reclaim_pending = static_cast<std::uint32_t>(freeable.size());
  return result;
}

ReclaimResult FakeKernel::reclaim(std::span<std::uint64_t> reclaim) {
  std::lock_guard lock(mutex_);
  ++calls_.reclaim;
  ReclaimResult result;
  std::deque<std::uint64_t>& freeable = reclaimable_[caller_pid_];
  while (result.reclaim_count < reclaim.size() && !freeable.empty()) {
    reclaim[result.reclaim_count++] = freeable.front();
    freeable.pop_front();
  }
  result.reclaim_pending = static_cast<std::uint32_t>(freeable.size());
  return result;
}

std::uint32_t FakeKernel::shed() {
  std::lock_guard lock(mutex_);
  ++calls_.shed;
  std::uint32_t shed = 0;
  for (auto& [handle, topic] : topics_) {
    for (auto& [id, subscriber] : topic.subscribers) {
      std::deque<std::uint64_t> kept;
      for (std::uint64_t entry_id : subscriber.unreceived) {
        const Entry& entry = entries_[entry_id];
        if (entry.pid == caller_pid_ && !entry.in_window) {
          drop_unreceived(subscriber, entry_id);
          ++shed;
        } else {
          kept.push_back(entry_id);
        }
      }
      subscriber.unreceived = std::move(kept);
    }
  }
  return shed;
}

ReceiveResult FakeKernel::receive(EndpointId subscriber_id, std::span<ReceivedEntry> entries,
                                  std::span<PoolGrant> pools,
                                  std::span<const std::uint64_t> release_ids) {
  std::lock_guard lock(mutex_);
  ++calls_.receive;
  if (entries.empty() || pools.empty() || release_ids.size() > release_max) fail("RECEIVE", EINVAL);
  break_overdue_promises();
  Subscriber& subscriber = subscriber_of(subscriber_id);
  if (subscriber.polling) fail("RECEIVE", EINVAL);
  // It looks whatever the answer, as in the module.
  subscriber.notified = false;
  release_held("RECEIVE", subscriber, release_ids);
  ReceiveResult result;
  const std::size_t capacity = std::min(entries.size(), receive_entries_max);
  while (result.entry_count < capacity && !subscriber.unreceived.empty()) {
    const std::uint64_t entry_id = subscriber.unreceived.front();
    subscriber.unreceived.pop_front();
    Entry& entry = entries_[entry_id];
    --entry.unreceived_by;
    ++entry.held_by;
    subscriber.held.insert(entry_id);
    ++subscriber.received;
    entries[result.entry_count++] = ReceivedEntry{entry_id, entry.addr, entry.publisher_id};
  }
  result.remaining = static_cast<std::uint32_t>(subscriber.unreceived.size());
  return result;
}

TakeResult FakeKernel::take(EndpointId subscriber_id) {
  std::lock_guard lock(mutex_);
  ++calls_.take;
  Subscriber& subscriber = subscriber_of(subscriber_id);
  if (!subscriber.polling) fail("TAKE", EINVAL);
  TakeResult result;
  if (subscriber.unreceived.empty()) return result;
  const std::uint64_t newest = subscriber.unreceived.back();
  subscriber.unreceived.pop_back();
  while (!subscriber.unreceived.empty()) {
    const std::uint64_t passed_over = subscriber.unreceived.front();
    subscriber.unreceived.pop_front();
    --entries_[passed_over].unreceived_by;
    settle(passed_over);
  }
  Entry& entry = entries_[newest];
  --entry.unreceived_by;
  ++entry.held_by;
  subscriber.held.insert(newest);
  ++subscriber.received;
  result.has_entry = true;
  result.entry = ReceivedEntry{newest, entry.addr, entry.publisher_id};
  return result;
}

void FakeKernel::release(EndpointId subscriber_id, std::span<const std::uint64_t> entry_ids) {
  std::lock_guard lock(mutex_);
  ++calls_.release;
  if (release_error_) fail("RELEASE", release_error_);
  if (entry_ids.empty() || entry_ids.size() > release_max) fail("RELEASE", EINVAL);
  release_held("RELEASE", subscriber_of(subscriber_id), entry_ids);
}

void FakeKernel::release_held(const char* call, Subscriber& subscriber,
                              std::span<const std::uint64_t> entry_ids) {
  std::set<std::uint64_t> listed;
  for (const std::uint64_t entry_id : entry_ids) {
    if (!subscriber.held.contains(entry_id) || !listed.insert(entry_id).second) fail(call, ENOENT);
  }
  for (const std::uint64_t entry_id : entry_ids) {
    subscriber.held.erase(subscriber.held.find(entry_id));
    --entries_[entry_id].held_by;
    settle(entry_id);
    ++calls_.released_entries;
  }
}

bool FakeKernel::topic_info(const std::string& name, TopicInfo& info) {
  std::lock_guard lock(mutex_);
  for (const auto& [handle, topic] : topics_) {
    if (topic.name != name || (topic.publishers.empty() && topic.subscribers.empty())) continue;
    info = TopicInfo{};
    info.name = name;
    info.type_name = topic.type_name;
    info.type_hash = topic.type_hash;
    info.entries = static_cast<std::uint32_t>(
        std::count_if(entries_.begin(), entries_.end(),
                      [&](const auto& entry) { return entry.second.topic_handle == handle; }));
    for (const auto& [id, publisher] : topic.publishers) {
      info.publishers.push_back(
          PublisherInfo{id, publisher.pid, publisher.node, publisher.depth,
                        publisher.transient_local, publisher.published, publisher.published_bytes,
                        static_cast<std::uint32_t>(publisher.window.size()), 0});
    }
    for (const auto& [id, subscriber] : topic.subscribers) {
      info.subscribers.push_back(SubscriberInfo{
          id, subscriber.pid, subscriber.node, subscriber.depth, subscriber.transient_local,
          subscriber.polling, static_cast<std::uint32_t>(subscriber.unreceived.size()),
          static_cast<std::uint32_t>(subscriber.held.size()), subscriber.received,
          subscriber.dropped, 0});
    }
    return true;
  }
  return false;
}

FakeKernel::Calls FakeKernel::calls() const {
  std::lock_guard lock(mutex_);
  return calls_;
}

std::size_t FakeKernel::live_entries() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

void FakeKernel::fail_releases(int err) {
  std::lock_guard lock(mutex_);
  release_error_ = err;
}

void FakeKernel::set_caller_pid(pid_t pid) {
  std::lock_guard lock(mutex_);
  caller_pid_ = pid;
}

}  // namespace agnocast::detail
