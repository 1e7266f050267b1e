// libagnocast_lttng.so: the probes of tracepoints.h, which libagnocast loads
// into a process that may be traced (tracepoints.cpp), or that a user
// preloads.
#define LTTNG_UST_TRACEPOINT_CREATE_PROBES
#include "tracing/tracepoints.h"
