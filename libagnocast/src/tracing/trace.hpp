// AGNOCAST_TRACE(event, args...): one of the LTTng-UST events of
// tracepoints.h. Its arguments are evaluated only while a session enables the
// event; built with AGNOCAST_TRACING=OFF, it is nothing at all.
#pragma once

#include <unistd.h>

#include <cstdint>

// AGNOCAST_TRACE_INIT(owner, emit): an init event, `emit` a lambda holding
// its AGNOCAST_TRACE with what it captured, sent now and again for a session
// that enables the events later, until AGNOCAST_FORGET_INIT(owner) when the
// owner goes (init_events.hpp); AGNOCAST_REPLAY_INIT() at each executor wait.
#ifdef AGNOCAST_TRACING
#include "tracing/init_events.hpp"
#include "tracing/tracepoints.h"
#define AGNOCAST_TRACE(event, ...) lttng_ust_tracepoint(agnocast, event, __VA_ARGS__)
#define AGNOCAST_TRACE_INIT(owner, ...) ::agnocast::detail::keep_init_event(owner, __VA_ARGS__)
#define AGNOCAST_FORGET_INIT(owner) ::agnocast::detail::forget_init_events(owner)
#define AGNOCAST_REPLAY_INIT() ::agnocast::detail::replay_init_events()
#else
#define AGNOCAST_TRACE(event, ...) static_cast<void>(0)
#define AGNOCAST_TRACE_INIT(owner, ...) static_cast<void>(0)
#define AGNOCAST_FORGET_INIT(owner) static_cast<void>(0)
#define AGNOCAST_REPLAY_INIT() static_cast<void>(0)
#endif

namespace agnocast::detail {

// Which callable of which process: the pid_ciid field of upstream's events,
// the process id above a subscription's id on its topic.
inline std::uint64_t callable_id(std::uint32_t subscriber_id) {
  return (static_cast<std::uint64_t>(::getpid()) << 32) | subscriber_id;
}

// A callback's callable_start now and its callable_end when this goes,
// whether the callback returned or threw.
class TracedCallable {
 public:
  explicit TracedCallable(const void* callable) : callable_(callable) {
    AGNOCAST_TRACE(agnocast_callable_start, callable);
  }
  ~TracedCallable() { AGNOCAST_TRACE(agnocast_callable_end, callable_); }
  TracedCallable(const TracedCallable&) = delete;
  TracedCallable& operator=(const TracedCallable&) = delete;

 private:
  [[maybe_unused]] const void* const callable_;
};

}  // namespace agnocast::detail
