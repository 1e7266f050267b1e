#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

#include "agnocast/detail/endpoints.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"
#include "endpoint_request.hpp"
#include "log_internal.hpp"
#include "node_state.hpp"
#include "notification_queue.hpp"
#include "runtime.hpp"

namespace agnocast::detail {
namespace {

// The kernel subscriber. It outlives its Subscription while any received
// message is still held, so that memory is never reclaimed under a reader.
// A callback subscriber's releases made while it handles a wake-up (messages
// dropped by its callbacks) ride on its next receive of that wake-up; what is
// left goes in one release when the wake-up ends, so that nothing stays held
// until the next message (a dead publisher's pool would stay with it). A full
// batch, and any release outside a wake-up, goes at once.
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
    pending_releases_[pending_count_++] = entry_id;
    if (handling_wakeup_ && pending_count_ < release_batch) return;
    release_pending();
  }

  // Called by the thread receiving, under the subscription's receive mutex:
  // from now until end_wakeup(), releases wait for the next receive or the end.
  void begin_wakeup() {
    std::lock_guard lock(release_mutex_);
    handling_wakeup_ = true;
  }

  // Releases what still waits, in one call.
  void end_wakeup() noexcept {
    std::lock_guard lock(release_mutex_);
    handling_wakeup_ = false;
    if (pending_count_ > 0) release_pending();
  }

  // Moves the releases waiting for the next receive into batch; returns their number.
  std::size_t take_releases(ReleaseBatch& batch) {
    std::lock_guard lock(release_mutex_);
    const std::size_t count = std::exchange(pending_count_, 0);
    std::copy_n(pending_releases_.begin(), count, batch.begin());
    return count;
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
  void release_pending() noexcept {
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
  ReleaseBatch pending_releases_{};
  std::size_t pending_count_ = 0;
  std::mutex spare_mutex_;  // releases come from any thread
  std::vector<EntryReference*> spare_references_;
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
  std::mutex receive_mutex;
};

SubscriptionBase::SubscriptionBase(std::shared_ptr<NodeState> node, std::string_view topic,
                                   const QoS& qos, const MessageType& type,
                                   const SubscriptionOptions& options)
    : Waitable(options.callback_group), state_(std::make_unique<State>()) {
  EndpointRequest request =
      make_endpoint_request(node->name, topic, qos, EndpointKind::callback_subscriber, type);
  request.ignore_local = options.ignore_local_publications;
  state_->node = std::move(node);
  state_->topic = request.topic;
  state_->endpoint = std::make_shared<SubscriberEndpoint>(Runtime::get(), request);
  // If the queue cannot be created, the endpoint's destructor removes the subscriber.
  state_->queue = std::make_unique<OwnedQueue>(
      agnocast::queue_name(topic, state_->endpoint->id().id), qos.depth());
  // Entries published before the queue existed woke nobody: wake ourselves.
  state_->queue->notify();
}

SubscriptionBase::~SubscriptionBase() {
  state_->node->remove_waitable(key());
  state_->endpoint.reset();  // removes the kernel subscriber unless messages are still held
  state_->queue.reset();     // then unlinks the queue
}

const std::string& SubscriptionBase::topic() const { return state_->topic; }
std::uint32_t SubscriptionBase::id() const { return state_->endpoint->id().id; }
const std::string& SubscriptionBase::queue_name() const { return state_->queue->name(); }
int SubscriptionBase::queue_fd() const { return state_->queue->fd(); }

std::size_t SubscriptionBase::handle_wakeup() {
  State& state = *state_;
  std::lock_guard lock(state.receive_mutex);
  Runtime& runtime = state.endpoint->runtime();
  std::array<ReceivedEntry, Kernel::receive_entries_max> entries;
  std::array<PoolGrant, Kernel::receive_pools_max> pools;
  std::size_t delivered = 0;
  // Receive until nothing is left, run the callbacks, then take the one
  // notification that woke us: three system calls with the executor's wait
  // whatever the depth, and one release at the end for what the callbacks
  // dropped.  A publisher commits its entry before it notifies, and the
  // notification taken was queued before the receive (the executor runs a
  // wake-up on one thread at a time), so its entry was received.  An entry
  // this receive missed has a notification still to come, or one still
  // queued (a queue refuses one only while full, and it holds two at least):
  // either wakes us again.  A queue that holds one only (fs.mqueue.msg_max
  // 1) is drained first instead.  A throwing callback leaves the
  // notification queued, for the entries it did not reach.
  const bool drain_after = state.queue->drains_after();
  if (!drain_after) state.queue->take_one();
  SubscriberEndpoint::ReleaseBatch releases;
  SubscriberEndpoint& endpoint = *state.endpoint;
  endpoint.begin_wakeup();
  struct EndWakeup {
    SubscriberEndpoint& endpoint;
    ~EndWakeup() { endpoint.end_wakeup(); }
  } end_wakeup{endpoint};
  for (;;) {
    const std::span<const std::uint64_t> released(releases.data(),
                                                  state.endpoint->take_releases(releases));
    ReceiveResult result;
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
      while (handed_out < result.entry_count) {
        const std::size_t i = handed_out++;
        deliver(reinterpret_cast<const void*>(entries[i].addr), references[i],
                info_of(runtime, entries[i]));
        ++delivered;
      }
    } catch (...) {
      for (std::size_t i = handed_out; i < result.entry_count; ++i) release(references[i]);
      throw;
    }
    if (result.remaining == 0) break;
  }
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
  EndpointRequest request =
      make_endpoint_request(node->name, topic, qos, EndpointKind::polling_subscriber, type);
  request.ignore_local = options.ignore_local_publications;
  state_->node = std::move(node);
  state_->topic = request.topic;
  state_->endpoint = std::make_shared<SubscriberEndpoint>(Runtime::get(), request);
}

PollingCore::~PollingCore() {
  if (state_->latest.reference) release(state_->latest.reference);
}

const std::string& PollingCore::topic() const { return state_->topic; }
std::uint32_t PollingCore::id() const { return state_->endpoint->id().id; }

// With take_mutex held: asks the kernel for the newest unreceived entry and
// makes it the latest. Returns false when there is none.
bool PollingCore::take_newer() {
  SubscriberEndpoint& endpoint = *state_->endpoint;
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
  if (!reference) return false;
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
