/* SPDX-License-Identifier: GPL-2.0 */
/*
 * agnocast: the module's trace events, system "agnocast" (tracefs
 * events/agnocast/, perf's agnocast:*).
 *
 * Each event fires where its thing happens, under the locks already held,
 * and takes pointers the caller has at hand: a disabled event costs its
 * static branch, an enabled one reads the fields it records.  The ids are
 * those the UAPI and agnocast-cli show: topic_id is the topic's handle
 * (ADD_PUBLISHER's and ADD_SUBSCRIBER's topic_handle), publisher_id and
 * subscriber_id are endpoint ids (topic_local_id), entry_id is PUBLISH's and
 * RECEIVE's, and pid is the init-namespace tgid of the process the event is
 * about: the publisher's (publish, reclaim: the pool's owner), the
 * subscriber's (receive, release, drop, shed) or the one that ends
 * (process_exit).
 */
#undef TRACE_SYSTEM
#define TRACE_SYSTEM agnocast

#ifndef _AGNOCAST_TRACE_ENUMS
#define _AGNOCAST_TRACE_ENUMS
/* Why a subscriber loses an entry it never received (agnocast:drop). */
enum agnocast_drop_reason {
	AGNOCAST_DROP_DEPTH,		/* its ring of depth was full: the oldest went */
	AGNOCAST_DROP_PASSED_OVER,	/* a TAKE took a newer one */
	AGNOCAST_DROP_REMOVED,		/* the subscriber went, or its process */
};
#endif

#ifdef AGNOCAST_UNTRACED
/*
 * The unit tests' copy of the engine (agnocast_kunit.c): agnocast.ko alone
 * defines the events, which a second module would collide with in tracefs.
 * And a module built without them (Kbuild's AGNOCAST_UNTRACED=1), which the
 * benchmarks' icount run sets against this one to measure what they cost.
 */
#define trace_publish(...) do { } while (0)
#define trace_receive(...) do { } while (0)
#define trace_release(...) do { } while (0)
#define trace_reclaim(...) do { } while (0)
#define trace_shed(...) do { } while (0)
#define trace_drop(...) do { } while (0)
#define trace_process_exit(...) do { } while (0)
#elif !defined(_AGNOCAST_TRACE_H) || defined(TRACE_HEADER_MULTI_READ)
#define _AGNOCAST_TRACE_H

#include <linux/pid.h>
#include <linux/tracepoint.h>
#include <linux/version.h>

#include "agnocast_internal.h"

/* 6.10 dropped __assign_str()'s source argument: __string() names it. */
#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 10, 0)
#define agnocast_assign_str(dst, src) __assign_str(dst)
#else
#define agnocast_assign_str(dst, src) __assign_str(dst, src)
#endif

TRACE_DEFINE_ENUM(AGNOCAST_DROP_DEPTH);
TRACE_DEFINE_ENUM(AGNOCAST_DROP_PASSED_OVER);
TRACE_DEFINE_ENUM(AGNOCAST_DROP_REMOVED);

/* A PUBLISH made @msg the newest of its topic and listed @woken subscribers. */
TRACE_EVENT(publish,
	TP_PROTO(const struct agnocast_publisher *pub,
		 const struct agnocast_topic_entry *msg, u64 bytes, u32 woken),
	TP_ARGS(pub, msg, bytes, woken),
	TP_STRUCT__entry(
		__string(topic, msg->topic->name)
		__field(u32, topic_id)
		__field(u64, entry_id)
		__field(u32, publisher_id)
		__field(pid_t, pid)
		__field(u64, bytes)
		__field(u32, woken)
	),
	TP_fast_assign(
		agnocast_assign_str(topic, msg->topic->name);
		__entry->topic_id = msg->topic->handle;
		__entry->entry_id = msg->id;
		__entry->publisher_id = pub->ep.id;
		__entry->pid = pub->ep.proc->tgid;
		__entry->bytes = bytes;
		__entry->woken = woken;
	),
	TP_printk("topic=%s topic_id=%u entry_id=%llu publisher_id=%u pid=%d bytes=%llu woken=%u",
		  __get_str(topic), __entry->topic_id, __entry->entry_id,
		  __entry->publisher_id, __entry->pid, __entry->bytes, __entry->woken)
);

/* What the events about one entry of one subscriber record. */
DECLARE_EVENT_CLASS(agnocast_sub_entry,
	TP_PROTO(const struct agnocast_subscriber *sub,
		 const struct agnocast_topic_entry *msg),
	TP_ARGS(sub, msg),
	TP_STRUCT__entry(
		__string(topic, msg->topic->name)
		__field(u32, topic_id)
		__field(u32, subscriber_id)
		__field(pid_t, pid)
		__field(u64, entry_id)
		__field(u32, publisher_id)
	),
	TP_fast_assign(
		agnocast_assign_str(topic, msg->topic->name);
		__entry->topic_id = msg->topic->handle;
		__entry->subscriber_id = sub->ep.id;
		__entry->pid = sub->ep.proc->tgid;
		__entry->entry_id = msg->id;
		__entry->publisher_id = msg->publisher_id;
	),
	TP_printk("topic=%s topic_id=%u subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u",
		  __get_str(topic), __entry->topic_id, __entry->subscriber_id,
		  __entry->pid, __entry->entry_id, __entry->publisher_id)
);

/*
 * A RECEIVE or TAKE handed @msg to @sub, one of the @entries that call
 * returns.
 */
TRACE_EVENT(receive,
	TP_PROTO(const struct agnocast_subscriber *sub,
		 const struct agnocast_topic_entry *msg, u32 entries),
	TP_ARGS(sub, msg, entries),
	TP_STRUCT__entry(
		__string(topic, msg->topic->name)
		__field(u32, topic_id)
		__field(u32, subscriber_id)
		__field(pid_t, pid)
		__field(u64, entry_id)
		__field(u32, publisher_id)
		__field(u32, entries)
	),
	TP_fast_assign(
		agnocast_assign_str(topic, msg->topic->name);
		__entry->topic_id = msg->topic->handle;
		__entry->subscriber_id = sub->ep.id;
		__entry->pid = sub->ep.proc->tgid;
		__entry->entry_id = msg->id;
		__entry->publisher_id = msg->publisher_id;
		__entry->entries = entries;
	),
	TP_printk("topic=%s topic_id=%u subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u entries=%u",
		  __get_str(topic), __entry->topic_id, __entry->subscriber_id,
		  __entry->pid, __entry->entry_id, __entry->publisher_id, __entry->entries)
);

/*
 * @sub gave back @msg it held: by RELEASE, by RECEIVE's release list, or
 * because it went.
 */
DEFINE_EVENT(agnocast_sub_entry, release,
	TP_PROTO(const struct agnocast_subscriber *sub,
		 const struct agnocast_topic_entry *msg),
	TP_ARGS(sub, msg)
);

/*
 * A SHED of @msg's publisher took @msg, out of its window, from @sub,
 * which had not received it.
 */
DEFINE_EVENT(agnocast_sub_entry, shed,
	TP_PROTO(const struct agnocast_subscriber *sub,
		 const struct agnocast_topic_entry *msg),
	TP_ARGS(sub, msg)
);

/* @sub lost @msg, unreceived, for @reason. */
TRACE_EVENT(drop,
	TP_PROTO(const struct agnocast_subscriber *sub,
		 const struct agnocast_topic_entry *msg, enum agnocast_drop_reason reason),
	TP_ARGS(sub, msg, reason),
	TP_STRUCT__entry(
		__string(topic, msg->topic->name)
		__field(u32, topic_id)
		__field(u32, subscriber_id)
		__field(pid_t, pid)
		__field(u64, entry_id)
		__field(u32, publisher_id)
		__field(u32, reason)
	),
	TP_fast_assign(
		agnocast_assign_str(topic, msg->topic->name);
		__entry->topic_id = msg->topic->handle;
		__entry->subscriber_id = sub->ep.id;
		__entry->pid = sub->ep.proc->tgid;
		__entry->entry_id = msg->id;
		__entry->publisher_id = msg->publisher_id;
		__entry->reason = reason;
	),
	TP_printk("topic=%s topic_id=%u subscriber_id=%u pid=%d entry_id=%llu publisher_id=%u reason=%s",
		  __get_str(topic), __entry->topic_id, __entry->subscriber_id,
		  __entry->pid, __entry->entry_id, __entry->publisher_id,
		  __print_symbolic(__entry->reason,
				   { AGNOCAST_DROP_DEPTH, "depth" },
				   { AGNOCAST_DROP_PASSED_OVER, "passed_over" },
				   { AGNOCAST_DROP_REMOVED, "removed" }))
);

/*
 * @msg's last reference went: its address waits on the pool owner's
 * reclaim list for a PUBLISH or RECLAIM to hand it back, or, the owner gone,
 * the entry is freed.
 */
TRACE_EVENT(reclaim,
	TP_PROTO(const struct agnocast_topic_entry *msg),
	TP_ARGS(msg),
	TP_STRUCT__entry(
		__string(topic, msg->topic->name)
		__field(u32, topic_id)
		__field(u64, entry_id)
		__field(u32, publisher_id)
		__field(pid_t, pid)
		__field(bool, freed)
	),
	TP_fast_assign(
		agnocast_assign_str(topic, msg->topic->name);
		__entry->topic_id = msg->topic->handle;
		__entry->entry_id = msg->id;
		__entry->publisher_id = msg->publisher_id;
		__entry->pid = pid_nr(msg->pool->owner_pid);
		__entry->freed = !msg->pool->owner;
	),
	TP_printk("topic=%s topic_id=%u entry_id=%llu publisher_id=%u pid=%d freed=%d",
		  __get_str(topic), __entry->topic_id, __entry->entry_id,
		  __entry->publisher_id, __entry->pid, __entry->freed)
);

/*
 * @proc's teardown begins (@exited: it exited or exec'd; else it called
 * UNREGISTER_PROCESS), with what it is about to clean: its endpoints, the
 * entries its subscribers hold and have unreceived, those in its
 * publishers' windows and its reclaimable addresses.  The namespace lock is
 * held for write, so the counts need no topic lock.
 */
TRACE_EVENT(process_exit,
	TP_PROTO(const struct agnocast_proc *proc, bool exited),
	TP_ARGS(proc, exited),
	TP_STRUCT__entry(
		__field(pid_t, pid)
		__field(bool, exited)
		__field(u32, publishers)
		__field(u32, subscribers)
		__field(u32, held)
		__field(u32, unreceived)
		__field(u32, window)
		__field(u32, reclaimable)
	),
	TP_fast_assign(
		const struct agnocast_subscriber *sub;
		const struct agnocast_publisher *pub;

		__entry->pid = proc->tgid;
		__entry->exited = exited;
		__entry->publishers = proc->nr_publishers;
		__entry->subscribers = proc->nr_subscribers;
		__entry->held = 0;
		__entry->unreceived = 0;
		__entry->window = 0;
		list_for_each_entry(sub, &proc->subscribers, ep.proc_node) {
			__entry->held += sub->nr_held;
			__entry->unreceived += sub->nr_unreceived;
		}
		list_for_each_entry(pub, &proc->publishers, ep.proc_node)
			__entry->window += pub->window_len;
		__entry->reclaimable = proc->nr_reclaim;
	),
	TP_printk("pid=%d exited=%d publishers=%u subscribers=%u held=%u unreceived=%u window=%u reclaimable=%u",
		  __entry->pid, __entry->exited, __entry->publishers, __entry->subscribers,
		  __entry->held, __entry->unreceived, __entry->window, __entry->reclaimable)
);

#endif /* _AGNOCAST_TRACE_H */

/* Outside the guard: define_trace.h reads the events again. */
#undef TRACE_INCLUDE_PATH
#define TRACE_INCLUDE_PATH .
#undef TRACE_INCLUDE_FILE
#define TRACE_INCLUDE_FILE agnocast_trace
#include <trace/define_trace.h>
