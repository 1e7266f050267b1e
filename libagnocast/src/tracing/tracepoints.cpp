// The probes of tracepoints.h, built into libagnocast: a process traces from
// its start, whenever an LTTng session enables the events, with nothing to
// preload. With no session they cost one load and branch each.
#define LTTNG_UST_TRACEPOINT_CREATE_PROBES
#define LTTNG_UST_TRACEPOINT_DEFINE
#include "tracing/tracepoints.h"
