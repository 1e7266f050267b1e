// The library's LTTng-UST events, provider `agnocast`. Names and fields
// follow upstream Agnocast's provider, so that tools joining its events
// (publish -> take -> callable by entry_id) read ours; what upstream does not
// have (node, timer, callback group, executor wait and wake, the ids
// agnocast-cli shows) is added after its fields. publish and take name their
// topic too: a session started after a process made its endpoints misses
// their init events, and can still follow every message.
//
// Included only through trace.hpp; LTTng-UST reads this header several times
// when it generates the probes (tracepoints.cpp), hence no #pragma once.

// clang-format off
#undef LTTNG_UST_TRACEPOINT_PROVIDER
#define LTTNG_UST_TRACEPOINT_PROVIDER agnocast

#undef LTTNG_UST_TRACEPOINT_INCLUDE
#define LTTNG_UST_TRACEPOINT_INCLUDE "tracing/tracepoints.h"

#if !defined(AGNOCAST_TRACING_TRACEPOINTS_H) || defined(LTTNG_UST_TRACEPOINT_HEADER_MULTI_READ)
#define AGNOCAST_TRACING_TRACEPOINTS_H

#include <lttng/tracepoint.h>
#include <stdint.h>

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_node_init,
  LTTNG_UST_TP_ARGS(const void *, node_handle_arg, const char *, node_name_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, node_handle, (uintptr_t)node_handle_arg)
    lttng_ust_field_string(node_name, node_name_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_publisher_init,
  LTTNG_UST_TP_ARGS(const void *, publisher_handle_arg, const void *, node_handle_arg,
                    const char *, topic_name_arg, uint64_t, queue_depth_arg,
                    uint32_t, publisher_id_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, publisher_handle, (uintptr_t)publisher_handle_arg)
    lttng_ust_field_integer_hex(uintptr_t, node_handle, (uintptr_t)node_handle_arg)
    lttng_ust_field_string(topic_name, topic_name_arg)
    lttng_ust_field_integer(uint64_t, queue_depth, queue_depth_arg)
    lttng_ust_field_integer(uint32_t, publisher_id, publisher_id_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_subscription_init,
  LTTNG_UST_TP_ARGS(const void *, subscription_handle_arg, const void *, node_handle_arg,
                    const void *, callback_arg, const void *, callback_group_arg,
                    const char *, symbol_arg, const char *, topic_name_arg,
                    uint64_t, queue_depth_arg, uint64_t, pid_ciid_arg,
                    uint32_t, subscriber_id_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, subscription_handle, (uintptr_t)subscription_handle_arg)
    lttng_ust_field_integer_hex(uintptr_t, node_handle, (uintptr_t)node_handle_arg)
    lttng_ust_field_integer_hex(uintptr_t, callback, (uintptr_t)callback_arg)
    lttng_ust_field_integer_hex(uintptr_t, callback_group, (uintptr_t)callback_group_arg)
    lttng_ust_field_string(symbol, symbol_arg)
    lttng_ust_field_string(topic_name, topic_name_arg)
    lttng_ust_field_integer(uint64_t, queue_depth, queue_depth_arg)
    lttng_ust_field_integer(uint64_t, pid_ciid, pid_ciid_arg)
    lttng_ust_field_integer(uint32_t, subscriber_id, subscriber_id_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_timer_init,
  LTTNG_UST_TP_ARGS(const void *, timer_handle_arg, const void *, node_handle_arg,
                    const void *, callback_group_arg, int64_t, period_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, timer_handle, (uintptr_t)timer_handle_arg)
    lttng_ust_field_integer_hex(uintptr_t, node_handle, (uintptr_t)node_handle_arg)
    lttng_ust_field_integer_hex(uintptr_t, callback, (uintptr_t)timer_handle_arg)
    lttng_ust_field_integer_hex(uintptr_t, callback_group, (uintptr_t)callback_group_arg)
    lttng_ust_field_integer(int64_t, period, period_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_callback_group_init,
  LTTNG_UST_TP_ARGS(const void *, callback_group_arg, const void *, node_handle_arg,
                    const char *, group_type_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, callback_group, (uintptr_t)callback_group_arg)
    lttng_ust_field_integer_hex(uintptr_t, node_handle, (uintptr_t)node_handle_arg)
    lttng_ust_field_string(group_type, group_type_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_construct_executor,
  LTTNG_UST_TP_ARGS(const void *, executor_addr_arg, const char *, executor_type_name_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, executor_addr, (uintptr_t)executor_addr_arg)
    lttng_ust_field_string(executor_type_name, executor_type_name_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_publish,
  LTTNG_UST_TP_ARGS(const void *, publisher_handle_arg, int64_t, entry_id_arg,
                    const char *, topic_name_arg, uint32_t, publisher_id_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, publisher_handle, (uintptr_t)publisher_handle_arg)
    lttng_ust_field_integer(int64_t, entry_id, entry_id_arg)
    lttng_ust_field_string(topic_name, topic_name_arg)
    lttng_ust_field_integer(uint32_t, publisher_id, publisher_id_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_take,
  LTTNG_UST_TP_ARGS(const void *, subscription_handle_arg, const void *, message_arg,
                    int64_t, entry_id_arg, const char *, topic_name_arg,
                    uint32_t, subscriber_id_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, subscription_handle, (uintptr_t)subscription_handle_arg)
    lttng_ust_field_integer_hex(uintptr_t, message, (uintptr_t)message_arg)
    lttng_ust_field_integer(int64_t, entry_id, entry_id_arg)
    lttng_ust_field_string(topic_name, topic_name_arg)
    lttng_ust_field_integer(uint32_t, subscriber_id, subscriber_id_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_create_callable,
  LTTNG_UST_TP_ARGS(const void *, callable_arg, int64_t, entry_id_arg, uint64_t, pid_ciid_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, callable, (uintptr_t)callable_arg)
    lttng_ust_field_integer(int64_t, entry_id, entry_id_arg)
    lttng_ust_field_integer(uint64_t, pid_ciid, pid_ciid_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_callable_start,
  LTTNG_UST_TP_ARGS(const void *, callable_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, callable, (uintptr_t)callable_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_callable_end,
  LTTNG_UST_TP_ARGS(const void *, callable_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, callable, (uintptr_t)callable_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_loan,
  LTTNG_UST_TP_ARGS(const void *, message_arg, uint64_t, size_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, message, (uintptr_t)message_arg)
    lttng_ust_field_integer(uint64_t, size, size_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_heap_scope_enter,
  LTTNG_UST_TP_ARGS(const void *, scope_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, scope, (uintptr_t)scope_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_heap_scope_exit,
  LTTNG_UST_TP_ARGS(const void *, scope_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, scope, (uintptr_t)scope_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_executor_wait,
  LTTNG_UST_TP_ARGS(const void *, executor_addr_arg, int32_t, timeout_ms_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, executor_addr, (uintptr_t)executor_addr_arg)
    lttng_ust_field_integer(int32_t, timeout_ms, timeout_ms_arg)))

LTTNG_UST_TRACEPOINT_EVENT(agnocast, agnocast_executor_wake,
  LTTNG_UST_TP_ARGS(const void *, executor_addr_arg, int32_t, ready_arg),
  LTTNG_UST_TP_FIELDS(
    lttng_ust_field_integer_hex(uintptr_t, executor_addr, (uintptr_t)executor_addr_arg)
    lttng_ust_field_integer(int32_t, ready, ready_arg)))

#endif  // AGNOCAST_TRACING_TRACEPOINTS_H

#include <lttng/tracepoint-event.h>
// clang-format on
