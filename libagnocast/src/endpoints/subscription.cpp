#include <sys/timerfd.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"
#include "delay/delay_file.hpp"
#include "endpoints/endpoint_request.hpp"
#include "endpoints/node_state.hpp"
#include "endpoints/notification_queue.hpp"
#include "kernel/runtime.hpp"
#include "log_internal.hpp"
#include "tracing/trace.hpp"

namespace agnocast::detail {
namespace {

// How long releases left by a wake-up may wait for the next one's receive
// before they go in a release of their own: the longest a message dropped by
// a callback, and so a dead publisher's pool, stays held when nothing else
// arrives.
constexpr std::chrono::milliseconds deferred_release_delay{4};

timespec to_timespec(std::chrono::nanoseconds duration) {
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(duration);
  return timespec{static_cast<time_t>(seconds.count()),
                  static_cast<long>((duration - seconds).count())};
}

// The kernel subscriber. It outlives its Subscription while any received
// message is still held, so that memory is never reclaimed under a reader.
// A callback subscriber's releases made while it handles a wake-up (messages
// dropped by its callbacks) ride on its next receive: of that wake-up, or of
// the next one.  What a wake-up leaves waits at most deferred_release_delay,
// then goes in one call (see ReleaseTimer): in an executor, the deadline is
// its wait's timeout, which costs no system call; else a one-shot timerfd,
// armed only while releases wait, is the owner's to watch.  A full batch, what
// a throwing callback's wake-up leaves, and any release outside a wake-up go
// at once.
class SubscriberEndpoint : public EntryOwner {
 public:
  // Releases one receive carries; a full batch is released at once.
  static constexpr std::size_t release_batch = Kernel::receive_entries_max;
  using ReleaseBatch = std::array<std::uint64_t, release_batch>;

  SubscriberEndpoint(Runtime& runtime, const EndpointRequest& request)
      : runtime_(runtime), id_(runtime.kernel().add_subscriber(request)) {
    spare_references_.reserve(spare_references_max);
  }

  ~SubscriberEndpoint() override {
    for (EntryReference* reference : spare_references_) delete reference;
    if (!still_ours()) return;
    try {
      runtime_.kernel().remove_subscriber(id_);
    } catch (const Error& error) {
      // Destructors cannot throw; the kernel drops everything at process exit.
      log(LogLevel::warning, std::string("removing a subscriber: ") + error.what());
    }
  }

  void release_entry(std::uint64_t entry_id) noexcept override {
    if (!still_ours()) return;
    std::lock_guard lock(release_mutex_);
    add_release(entry_id);
  }

  // Called by the thread receiving, under the subscription's receive mutex:
  // from now until end_wakeup(), releases wait for the next receive or the
  // end.  Moves what waits for this wake-up's first receive into batch (as
  // take_releases()); returns their number.
  std::size_t begin_wakeup(ReleaseBatch& batch) {
    std::lock_guard lock(release_mutex_);
    handling_wakeup_ = true;
    return take_pending(batch);
  }

  // What still waits rides on the next receive once the timer is armed
  // (completed: no callback threw); else it goes now, in one call.
  void end_wakeup(bool completed) noexcept {
    std::lock_guard lock(release_mutex_);
    handling_wakeup_ = false;
    if (pending_count_ == 0) return;
    if (completed && arm_deferred_release()) return;
    release_pending();
  }

  // From now on, what a wake-up leaves waits for the next receive, at most
  // until timer_fd (a timerfd the caller owns) expires.
  void defer_releases(int timer_fd) {
    std::lock_guard lock(release_mutex_);
    timer_fd_ = timer_fd;
  }

  // The timer's descriptor is about to close: nothing waits any more.
  void stop_deferring() noexcept {
    if (!still_ours()) return;
    std::lock_guard lock(release_mutex_);
    timer_fd_ = -1;
    timer_armed_ = false;
    if (pending_count_ > 0 && !handling_wakeup_) release_pending();
  }

  // The timer expired: releases still waiting go now, unless a wake-up is
  // under way (its receive takes them, or its end arms the timer again).
  void release_deferred() noexcept {
    if (!still_ours()) return;
    std::lock_guard lock(release_mutex_);
    timer_armed_ = false;
    deadline_.store(no_deadline, std::memory_order_relaxed);
    if (pending_count_ > 0 && !handling_wakeup_) release_pending();
  }

  // An executor watches the deadline of what waits (watched), or stops to.
  // With none left, the timerfd bounds the wait again; what waits when the
  // last one stops goes now.
  void watch_deadline(bool watched) noexcept {
    if (!still_ours()) return;
    std::lock_guard lock(release_mutex_);
    if (watched) {
      ++deadline_watchers_;
      return;
    }
    if (deadline_watchers_ > 0 && --deadline_watchers_ == 0) {
      deadline_.store(no_deadline, std::memory_order_relaxed);
      if (pending_count_ > 0 && !handling_wakeup_) release_pending();
    }
  }

  // When what waits must go, for the executors that watch it.
  Waitable::Clock::time_point deadline() const noexcept {
    return Waitable::Clock::time_point(
        Waitable::Clock::duration(deadline_.load(std::memory_order_relaxed)));
  }

  // Moves the releases waiting for the next receive into batch; returns their number.
  std::size_t take_releases(ReleaseBatch& batch) {
    std::lock_guard lock(release_mutex_);
    return take_pending(batch);
  }

  // A failed receive released nothing: the ids wait for the next one, or
  // are released now if newer ones filled the batch meanwhile.
  void return_releases(std::span<const std::uint64_t> ids) noexcept {
    for (const std::uint64_t id : ids) release_entry(id);
  }

  // A spare reference when there is one, so that receiving allocates nothing
  // once as many messages as a callback holds at a time have passed.
  EntryReference* reference_to(std::uint64_t entry_id, std::shared_ptr<EntryOwner> self) {
    EntryReference* reference = nullptr;
    {
      std::lock_guard lock(spare_mutex_);
      if (!spare_references_.empty()) {
        reference = spare_references_.back();
        spare_references_.pop_back();
      }
    }
    if (!reference) reference = new EntryReference;
    reference->count.store(1, std::memory_order_relaxed);
    reference->owner = std::move(self);
    reference->entry_id = entry_id;
    return reference;
  }

  void recycle(EntryReference* reference) noexcept override {
    {
      std::lock_guard lock(spare_mutex_);
      if (spare_references_.size() < spare_references_max) {
        spare_references_.push_back(reference);  // within the reserved capacity: no allocation
        return;
      }
    }
    delete reference;
  }

  Runtime& runtime() const { return runtime_; }
  EndpointId id() const { return id_; }

 private:
  // False in a fork child: the endpoint and its references are the parent's.
  bool still_ours() const { return Runtime::current() == &runtime_; }

  // With release_mutex_ held.
  void add_release(std::uint64_t entry_id) noexcept {
    pending_releases_[pending_count_++] = entry_id;
    if (handling_wakeup_ && pending_count_ < release_batch) return;
    release_pending();
  }

  // With release_mutex_ held.
  std::size_t take_pending(ReleaseBatch& batch) noexcept {
    deadline_.store(no_deadline, std::memory_order_relaxed);
    const std::size_t count = std::exchange(pending_count_, 0);
    std::copy_n(pending_releases_.begin(), count, batch.begin());
    return count;
  }

  // With release_mutex_ held. False when there is no timer to wait for.
  bool arm_deferred_release() noexcept {
    if (deadline_watchers_ > 0) {
      if (deadline_.load(std::memory_order_relaxed) == no_deadline) {
        const auto due = Waitable::Clock::now() + deferred_release_delay;
        deadline_.store(due.time_since_epoch().count(), std::memory_order_relaxed);
      }
      return true;
    }
    if (timer_fd_ < 0) return false;
    if (timer_armed_) return true;  // it expires soon enough already
    const itimerspec once{timespec{}, to_timespec(deferred_release_delay)};
    if (::timerfd_settime(timer_fd_, 0, &once, nullptr) != 0) return false;
    timer_armed_ = true;
    return true;
  }

  // With release_mutex_ held.
  void release_pending() noexcept {
    deadline_.store(no_deadline, std::memory_order_relaxed);
    try {
      runtime_.kernel().release(id_, std::span(pending_releases_.data(), pending_count_));
    } catch (const Error& error) {
      // Called when the last pointer to a message goes: nobody to throw to.
      log(LogLevel::warning, std::string("releasing a received message: ") + error.what());
    }
    pending_count_ = 0;
  }

  // As many as one receive delivers; more held at once are allocated and freed.
  static constexpr std::size_t spare_references_max = Kernel::receive_entries_max;

  Runtime& runtime_;
  const EndpointId id_;
  std::mutex release_mutex_;
  bool handling_wakeup_ = false;
  int timer_fd_ = -1;
  bool timer_armed_ = false;
  static constexpr Waitable::Clock::rep no_deadline =
      Waitable::Clock::time_point::max().time_since_epoch().count();
  int deadline_watchers_ = 0;  // executors watching deadline_
  std::atomic<Waitable::Clock::rep> deadline_{no_deadline};
  ReleaseBatch pending_releases_{};
  std::size_t pending_count_ = 0;
  std::mutex spare_mutex_;  // releases come from any thread
  std::vector<EntryReference*> spare_references_;
};

// The deferred release's deadline, in the executor's set beside its
// subscription: the executor's wait times out at it (see Waitable::deadline).
// Its one-shot timerfd is armed only when no executor watches the deadline.
// Its expiry is housekeeping: spin_once() does not count it.
class ReleaseTimer : public Waitable {
 public:
  ReleaseTimer(std::shared_ptr<CallbackGroup> group, std::shared_ptr<SubscriberEndpoint> endpoint)
      : Waitable(std::move(group)),
        fd_(::timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK)),
        endpoint_(std::move(endpoint)) {
    if (fd_ < 0) throw Error(std::string("agnocast: timerfd_create: ") + std::strerror(errno));
  }
  ~ReleaseTimer() override { ::close(fd_); }

  int wait_fd() const override { return fd_; }
  bool housekeeping() const override { return true; }
  bool watch_deadline(bool watched) override {
    endpoint_->watch_deadline(watched);
    return true;
  }
  Clock::time_point deadline() const override { return endpoint_->deadline(); }
  void expire() override { endpoint_->release_deferred(); }
  void execute() override {
    std::uint64_t expirations = 0;
    if (::read(fd_, &expirations, sizeof expirations) != sizeof expirations) return;
    endpoint_->release_deferred();
  }

 private:
  const int fd_;
  const std::shared_ptr<SubscriberEndpoint> endpoint_;
};

// Maps every granted pool (closing each descriptor) and throws the first failure.
void map_pools(Runtime& runtime, std::span<const PoolGrant> pools) {
  std::exception_ptr failure;
  for (const PoolGrant& pool : pools) {
    try {
      runtime.map_pool(pool);
    } catch (...) {
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

// What the callback may learn besides the message, from the kernel and the header.
MessageInfo info_of(Runtime& runtime, const ReceivedEntry& entry) {
  const auto* message = reinterpret_cast<const void*>(entry.addr);
  const std::span<const std::byte> pool = runtime.pool_holding(message);
  const Publication publication = read_publication(message, pool.data(), pool.size());
  return MessageInfo{entry.publisher_id, entry.entry_id, publication.publish_time,
                     publication.bytes};
}

}  // namespace

std::size_t publisher_count(const std::string& topic) {
  TopicInfo info;
  if (!Runtime::get().kernel().topic_info(topic, info)) return 0;
  return info.publishers.size();
}

struct SubscriptionBase::State {
  std::shared_ptr<NodeState> node;
  std::string topic;
  std::shared_ptr<SubscriberEndpoint> endpoint;
  std::unique_ptr<OwnedQueue> queue;
  std::shared_ptr<ReleaseTimer> release_timer;
  std::mutex receive_mutex;
  std::unique_ptr<DelayRecorder> delays;  // written under receive_mutex
};

SubscriptionBase::SubscriptionBase(std::shared_ptr<NodeState> node, std::string_view topic,
                                   const QoS& qos, const MessageType& type,
                                   const SubscriptionOptions& options, TopicUse use)
    : Waitable(options.callback_group), state_(std::make_unique<State>()) {
  EndpointRequest request =
      make_endpoint_request(node->name, topic, qos, EndpointKind::callback_subscriber, type, use);
  request.ignore_local = options.ignore_local_publications;
  state_->node = std::move(node);
  state_->topic = request.topic;
  state_->endpoint = std::make_shared<SubscriberEndpoint>(Runtime::get(), request);
  AGNOCAST_TRACE_INIT(this, [subscription = this, node = state_->node.get(), group = group().get(),
                             symbol = std::string(type.name), topic = state_->topic.c_str(),
                             depth = qos.depth(), id = id()] {
    AGNOCAST_TRACE(agnocast_subscription_init, subscription, node, subscription, group,
                   symbol.c_str(), topic, depth, callable_id(id), id);
  });
  // A service's carriers are not topics anyone asks the delay of.
  state_->delays = use == TopicUse::application
                       ? std::make_unique<DelayRecorder>(state_->topic, state_->endpoint->id().id)
                       : std::make_unique<DelayRecorder>();
  // If the queue cannot be created, the endpoint's destructor removes the subscriber.
  state_->queue = std::make_unique<OwnedQueue>(
      agnocast::queue_name(topic, state_->endpoint->id().id), qos.depth());
  state_->release_timer = std::make_shared<ReleaseTimer>(group(), state_->endpoint);
  state_->endpoint->defer_releases(state_->release_timer->wait_fd());
  register_waitable(*state_->node, state_->release_timer);
  // Entries published before the queue existed woke nobody: wake ourselves.
  state_->queue->notify();
}

SubscriptionBase::~SubscriptionBase() {
  AGNOCAST_FORGET_INIT(this);
  state_->node->remove_waitable(key());
  state_->node->remove_waitable(state_->release_timer->key());
  state_->endpoint->stop_deferring();  // what waits goes now
  state_->release_timer.reset();       // closes the timer, which leaves the epoll sets
  state_->endpoint.reset();  // removes the kernel subscriber unless messages are still held
  state_->queue.reset();     // then unlinks the queue
}

const std::string& SubscriptionBase::topic() const { return state_->topic; }
std::uint32_t SubscriptionBase::id() const { return state_->endpoint->id().id; }
const std::string& SubscriptionBase::queue_name() const { return state_->queue->name(); }
int SubscriptionBase::queue_fd() const { return state_->queue->fd(); }
int SubscriptionBase::release_timer_fd() const { return state_->release_timer->wait_fd(); }
void SubscriptionBase::release_deferred() { state_->release_timer->execute(); }

std::size_t SubscriptionBase::handle_wakeup() {
  State& state = *state_;
  std::lock_guard lock(state.receive_mutex);
  Runtime& runtime = state.endpoint->runtime();
  std::array<ReceivedEntry, Kernel::receive_entries_max> entries;
  std::array<PoolGrant, Kernel::receive_pools_max> pools;
  std::size_t delivered = 0;
  // Receive until nothing is left, run the callbacks, then take the one
  // notification that woke us: with the executor's wait, three system calls
  // whatever the depth, the releases of what the callbacks dropped riding on
  // the next wake-up's receive (or going in one call when the timer armed at
  // the end of this one expires first).  A publisher commits its entry before it notifies, and the
  // notification taken was queued before the receive (the executor runs a
  // wake-up on one thread at a time), so its entry was received.  An entry
  // this receive missed has a notification still to come, or one still
  // queued (a queue refuses one only while full, and it holds two at least):
  // either wakes us again.  A queue that holds one only (fs.mqueue.msg_max
  // 1) is drained first instead.  A throwing callback, or a failing receive,
  // leaves the notification queued, for the entries it did not reach: the
  // module counts even a failed RECEIVE as looking, so nothing else would
  // wake us for them.
  const bool drain_after = state.queue->drains_after();
  struct Requeue {
    const OwnedQueue& queue;
    const int exceptions = std::uncaught_exceptions();
    bool taken = false;
    ~Requeue() {
      if (taken && std::uncaught_exceptions() > exceptions) queue.notify();
    }
  } requeue{*state.queue};
  if (!drain_after) requeue.taken = state.queue->take_one();
  SubscriberEndpoint::ReleaseBatch releases;
  SubscriberEndpoint& endpoint = *state.endpoint;
  std::size_t release_count = endpoint.begin_wakeup(releases);
  struct EndWakeup {
    SubscriberEndpoint& endpoint;
    bool completed = false;  // no callback threw
    ~EndWakeup() { endpoint.end_wakeup(completed); }
  } end_wakeup{endpoint};
  for (bool first = true;; first = false) {
    if (!first) release_count = endpoint.take_releases(releases);
    const std::span<const std::uint64_t> released(releases.data(), release_count);
    ReceiveResult result;
    std::unique_lock grants(runtime.grant_mutex());  // until its pools are mapped
    try {
      result = runtime.kernel().receive(state.endpoint->id(), entries, pools, released);
    } catch (...) {
      state.endpoint->return_releases(released);
      throw;
    }
    std::array<EntryReference*, Kernel::receive_entries_max> references;
    for (std::uint32_t i = 0; i < result.entry_count; ++i) {
      references[i] = state.endpoint->reference_to(entries[i].entry_id, state.endpoint);
    }
    std::size_t handed_out = 0;  // deliver() owns every reference it was given
    try {
      map_pools(runtime, std::span(pools.data(), result.pool_count));
      grants.unlock();
      while (handed_out < result.entry_count) {
        const std::size_t i = handed_out++;
        const MessageInfo info = info_of(runtime, entries[i]);
        state.delays->record(info.publish_time);
        const auto* message = reinterpret_cast<const void*>(entries[i].addr);
        AGNOCAST_TRACE(agnocast_take, this, message, static_cast<std::int64_t>(info.entry_id),
                       state.topic.c_str(), id());
        AGNOCAST_TRACE(agnocast_create_callable, this, static_cast<std::int64_t>(info.entry_id),
                       callable_id(id()));
        const TracedCallable callable(this);
        deliver(message, references[i], info);
        ++delivered;
      }
    } catch (...) {
      for (std::size_t i = handed_out; i < result.entry_count; ++i) release(references[i]);
      throw;
    }
    if (result.remaining == 0) break;
  }
  end_wakeup.completed = true;
  if (drain_after) state.queue->take_one();
  return delivered;
}

struct PollingCore::State {
  std::shared_ptr<NodeState> node;
  std::string topic;
  std::shared_ptr<SubscriberEndpoint> endpoint;
  std::mutex take_mutex;
  // The message taken last, held for take_latest() to give again.
  TakenEntry latest;
};

PollingCore::PollingCore(std::shared_ptr<NodeState> node, std::string_view topic, const QoS& qos,
                         const MessageType& type, const SubscriptionOptions& options)
    : state_(std::make_unique<State>()) {
  EndpointRequest request = make_endpoint_request(
      node->name, topic, qos, EndpointKind::polling_subscriber, type, TopicUse::application);
  request.ignore_local = options.ignore_local_publications;
  state_->node = std::move(node);
  state_->topic = request.topic;
  state_->endpoint = std::make_shared<SubscriberEndpoint>(Runtime::get(), request);
  AGNOCAST_TRACE_INIT(
      this, [subscription = this, node = state_->node.get(), symbol = std::string(type.name),
             topic = state_->topic.c_str(), depth = qos.depth(), id = id()] {
        AGNOCAST_TRACE(agnocast_subscription_init, subscription, node, nullptr, nullptr,
                       symbol.c_str(), topic, depth, callable_id(id), id);
      });
}

PollingCore::~PollingCore() {
  AGNOCAST_FORGET_INIT(this);
  if (state_->latest.reference) release(state_->latest.reference);
}

const std::string& PollingCore::topic() const { return state_->topic; }
std::uint32_t PollingCore::id() const { return state_->endpoint->id().id; }

// With take_mutex held: asks the kernel for the newest unreceived entry and
// makes it the latest. Returns false when there is none.
bool PollingCore::take_newer() {
  SubscriberEndpoint& endpoint = *state_->endpoint;
  std::unique_lock grants(endpoint.runtime().grant_mutex());  // until its pool is mapped
  const TakeResult taken = endpoint.runtime().kernel().take(endpoint.id());
  EntryReference* reference =
      taken.has_entry ? endpoint.reference_to(taken.entry.entry_id, state_->endpoint) : nullptr;
  if (taken.has_pool) {
    try {
      endpoint.runtime().map_pool(taken.pool);
    } catch (...) {
      if (reference) release(reference);
      throw;
    }
  }
  grants.unlock();
  if (!reference) return false;
  AGNOCAST_TRACE(agnocast_take, this, reinterpret_cast<const void*>(taken.entry.addr),
                 static_cast<std::int64_t>(taken.entry.entry_id), state_->topic.c_str(), id());
  if (state_->latest.reference) release(state_->latest.reference);
  state_->latest = TakenEntry{reinterpret_cast<const void*>(taken.entry.addr), reference};
  return true;
}

TakenEntry PollingCore::take_new() {
  std::lock_guard lock(state_->take_mutex);
  if (!take_newer()) return {};
  retain(state_->latest.reference);
  return state_->latest;
}

TakenEntry PollingCore::take_latest() {
  std::lock_guard lock(state_->take_mutex);
  take_newer();
  if (!state_->latest.reference) return {};
  retain(state_->latest.reference);
  return state_->latest;
}

}  // namespace agnocast::detail
