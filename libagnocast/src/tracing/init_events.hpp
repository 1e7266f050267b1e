// The init events (node, callback group, publisher, subscription, timer,
// executor) of what lives in this process, kept for a session that starts
// later: a process made its endpoints long before anyone ran `trace record`,
// and without them a tool cannot name a timer's callbacks or join a publish
// to its node. Each is sent when its object is made and again, once, whenever
// the events go from disabled to enabled; executors look at each wait.
// Used through trace.hpp's macros; nothing here without AGNOCAST_TRACING.
#pragma once

#include <functional>

namespace agnocast::detail {

// Sends the event (`emit` holds its AGNOCAST_TRACE) and keeps it for `owner`.
// Nothing is kept where the probes were never loaded: then no session can
// ever enable the events.
void keep_init_event(const void* owner, std::function<void()> emit);
// `owner` is gone: its events are not sent again.
void forget_init_events(const void* owner);
// Sends every kept event not yet sent since the events were last enabled.
// One load and one branch while nothing changed.
void replay_init_events();

// Whether libagnocast_lttng.so was loaded at the process's start.
bool probes_loaded();

}  // namespace agnocast::detail
