#include "tracing/init_events.hpp"

#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "tracing/tracepoints.h"

namespace agnocast::detail {
namespace {

struct Kept {
  const void* owner;
  std::function<void()> emit;
  bool sent;  // since the events were last enabled
};

struct InitEvents {
  std::mutex mutex;
  std::vector<Kept> kept;  // in the order their objects were made
  std::atomic<bool> enabled_seen{false};
};

InitEvents*& registry();

// A fork child starts with none: what it inherited is its parent's (and
// another thread may have held the mutex as the process forked).
InitEvents* make_registry() {
  ::pthread_atfork(nullptr, nullptr, [] { registry() = new InitEvents; });
  return new InitEvents;
}

// Never destroyed: objects may go, and executors wait, during static
// destruction.
InitEvents*& registry() {
  static InitEvents* events = make_registry();
  return events;
}

InitEvents& init_events() { return *registry(); }

// agnocast_node_init stands for the provider's events: sessions enable them
// together (`agnocast:*`).
bool enabled() { return lttng_ust_tracepoint_enabled(agnocast, agnocast_node_init); }

}  // namespace

void keep_init_event(const void* owner, std::function<void()> emit) {
  emit();
  if (!probes_loaded()) return;
  InitEvents& events = init_events();
  const std::lock_guard lock(events.mutex);
  events.kept.push_back({owner, std::move(emit), enabled()});
}

void forget_init_events(const void* owner) {
  if (!probes_loaded()) return;
  InitEvents& events = init_events();
  const std::lock_guard lock(events.mutex);
  std::erase_if(events.kept, [owner](const Kept& kept) { return kept.owner == owner; });
}

void replay_init_events() {
  if (!probes_loaded()) return;
  InitEvents& events = init_events();
  const bool now = enabled();
  if (now == events.enabled_seen.load(std::memory_order_relaxed)) return;
  const std::lock_guard lock(events.mutex);
  events.enabled_seen.store(now, std::memory_order_relaxed);
  for (Kept& kept : events.kept) {
    if (now && !kept.sent) kept.emit();
    kept.sent = now;
  }
}

}  // namespace agnocast::detail
