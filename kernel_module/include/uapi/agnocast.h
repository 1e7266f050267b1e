/* SPDX-License-Identifier: GPL-2.0 WITH Linux-syscall-note */
/*
 * agnocast: the one interface between agnocast.ko and user space.
 *
 * Everything here is fixed-width; user pointers travel as __u64; every
 * reserved or padding field must be zero on input (-EINVAL otherwise) and is
 * zero on output.  Strings are NUL-terminated inside their array; a missing
 * terminator is -EINVAL.
 *
 * Errors common to every command:
 *   -EFAULT  an argument or a buffer it names is not accessible
 *   -EINVAL  nonzero padding/reserved field, unknown flag, bad string
 *   -ENOTTY  unknown command
 *   -ENOMEM  the kernel could not allocate bookkeeping memory
 * Commands acting on endpoints or entries additionally return:
 *   -ESRCH   the calling process is not registered (REGISTER_PROCESS first)
 *   -EXDEV   the caller moved to another IPC namespace since registering
 *   -ENOENT  no such topic handle, endpoint id or entry
 *   -EPERM   the endpoint belongs to another process
 *
 * Processes are identified by their thread-group id.  A process that dies
 * (any signal, any thread count) or execs loses every endpoint and reference
 * it held; an exit record is queued for the daemon (see read() below).
 *
 * State is per IPC namespace: topics, ids and exit records of one namespace
 * are invisible from another.
 *
 * Only 64-bit processes can use the device: pools live above 4 GiB, so there
 * is no compat_ioctl and a 32-bit caller gets -ENOTTY.
 *
 * Answers are staged: every output buffer a command names is checked
 * writable before the command changes anything (-EFAULT then, and nothing
 * happened) and written after the kernel's locks are dropped.  Should another
 * thread unmap an output buffer in between, the command has happened and
 * still returns 0; what it could not write is lost, except reclaimable
 * addresses, which stay pending.
 */
#ifndef _UAPI_LINUX_AGNOCAST_H
#define _UAPI_LINUX_AGNOCAST_H

#include <linux/ioctl.h>
#include <linux/types.h>

#define AGNOCAST_DEVICE_PATH "/dev/agnocast"

/* The module and the library must agree on major and minor. */
#define AGNOCAST_VERSION_MAJOR 0
#define AGNOCAST_VERSION_MINOR 5
#define AGNOCAST_VERSION_PATCH 0

/* Including the terminating NUL. */
#define AGNOCAST_TOPIC_NAME_MAX 256
#define AGNOCAST_NODE_NAME_MAX 128
#define AGNOCAST_TYPE_NAME_MAX 128
/*
 * A topic's schema: an opaque description of its type, for tools.  Charged
 * to the memory cgroup of the process whose endpoint brought it.
 */
#define AGNOCAST_SCHEMA_MAX 65536

#define AGNOCAST_DEPTH_MAX 1024
#define AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX 1024
#define AGNOCAST_PUBLISHERS_PER_TOPIC_MAX 1024

/* Endpoint flags (add_publisher / add_subscriber). */
#define AGNOCAST_TRANSIENT_LOCAL (1U << 0)
/* Subscriber only: woken by nobody, reads with TAKE instead of RECEIVE. */
#define AGNOCAST_POLLING (1U << 1)
/*
 * Subscriber only: entries published by the subscriber's own process are
 * never queued for it (nor woken for, nor given as transient-local history),
 * so they never take its depth.
 */
#define AGNOCAST_IGNORE_LOCAL (1U << 2)
/*
 * Subscriber only, not with AGNOCAST_POLLING: woken once until it looks.  A
 * PUBLISH lists it in wake_ids only if no PUBLISH did since its last RECEIVE
 * (or TAKE, whatever either returned), so its publishers send it one
 * notification between two of its RECEIVEs, however many entries they
 * publish meanwhile.  Nothing waits unnoticed as long as the subscriber,
 * once woken, RECEIVEs until `remaining` is 0 (taking the notification that
 * woke it before or after): every entry published after that RECEIVE looked
 * wakes it again.  A notification sent to a full queue may be dropped: one
 * is waiting.
 *
 * A listing is a promise that the publisher's process keeps by sending the
 * notification.  When it may not have been kept, the subscriber is listed
 * again by the next PUBLISH and its process's wake eventfd (REGISTER_PROCESS)
 * is signalled at once: when the publisher's process dies while the
 * subscriber has not looked since, and when the publisher reports that it
 * could not notify (NOTIFY_FAILED).  When the subscriber has not looked
 * AGNOCAST_WAKE_WATCHDOG_MS after it was first listed, whatever the cause (a
 * stopped publisher, a queue replaced under its name, or just a busy or
 * stopped subscriber), its process's wake eventfd is signalled, once per
 * listing, and nothing more.  The same holds for callback subscribers
 * without the flag, which are listed by every PUBLISH.
 */
#define AGNOCAST_WAKE_ONCE (1U << 4)
#define AGNOCAST_WAKE_WATCHDOG_MS 50

/*
 * AGNOCAST_IOC_GET_VERSION: never fails but for -EFAULT.
 */
struct agnocast_version {
	__u32 major;
	__u32 minor;
	__u32 patch;
	__u32 reserved;
};

/*
 * AGNOCAST_IOC_REGISTER_PROCESS: make the caller a participant.
 *
 * Registration is two-step.  First pool_fd = -1: the kernel reserves a slot
 * and reports pool_addr and pool_size, the same virtual range in every
 * process of the namespace, and pid, the caller's pid as it sees itself.
 * The caller then maps a memfd of pool_size bytes writable at pool_addr,
 * seals it with AGNOCAST_POOL_SEALS and calls again with pool_fd set to
 * attach it.  The seals make the caller's existing mapping the only way to
 * write the pool: every new writable mapping, write() and size change fails
 * for every process, whoever opens the file.  The kernel keeps its own
 * read-only reopening of the file and hands that to subscribers.  Repeating
 * the first step returns the same slot.
 *
 *   -EBUSY   pool already attached
 *   -ENOSPC  every pool slot is in use (module parameter pool_count)
 *   -EBADF   pool_fd is not an open descriptor
 *   -EINVAL  pool_fd is not a readable memfd (shmem) file, or smaller than
 *            pool_size
 *   -EPERM   pool_fd lacks one of AGNOCAST_POOL_SEALS (F_SEAL_WRITE is
 *            accepted in place of F_SEAL_FUTURE_WRITE)
 *
 * With AGNOCAST_REGISTER_WAKE_EVENTFD in flags, either step also sets the
 * process's wake eventfd to wake_fd, once for the registration: the module
 * signals it when a notification to one of the process's callback
 * subscribers may have been lost (AGNOCAST_WAKE_ONCE), and the process
 * should then make each of them RECEIVE.  Without the flag wake_fd must be
 * 0.
 *
 *   -EBADF   wake_fd is not an open descriptor
 *   -EINVAL  wake_fd is not an eventfd
 *   -EEXIST  the process has a wake eventfd already
 */
#define AGNOCAST_POOL_SEALS \
	(0x0002 /* F_SEAL_SHRINK */ | 0x0004 /* F_SEAL_GROW */ | \
	 0x0010 /* F_SEAL_FUTURE_WRITE */ | 0x0001 /* F_SEAL_SEAL */)

#define AGNOCAST_REGISTER_WAKE_EVENTFD (1U << 0)

struct agnocast_register_process {
	__s32 pool_fd;
	__s32 pid;
	__u64 pool_addr;
	__u64 pool_size;
	__u32 flags;		/* AGNOCAST_REGISTER_WAKE_EVENTFD or 0 */
	__s32 wake_fd;
};

/*
 * AGNOCAST_IOC_UNREGISTER_PROCESS (no argument): drop every endpoint and
 * reference of the caller and free its slot, as if it had exited, but queue
 * no exit record.  -ESRCH if not registered.
 */

/*
 * AGNOCAST_IOC_ADD_PUBLISHER, AGNOCAST_IOC_ADD_SUBSCRIBER
 *
 * in:  topic name (starts with '/', [A-Za-z0-9_/], no "//", no trailing '/'),
 *      node label (printable ASCII, may be empty), depth 1..DEPTH_MAX, flags.
 * out: topic_handle (valid until the topic has no endpoints and no entries)
 *      and id, the topic_local_id.  Ids are never reused among topics whose
 *      names are equal once every '/' after the first is mapped to '_', so
 *      that their notification queue names never collide.
 *
 * A topic has one message type, fixed by the endpoint that creates it: its
 * type_name (printable ASCII, may be empty) and type_hash, and, from the
 * first endpoint that brings one, its schema (schema_size bytes at schema,
 * at most AGNOCAST_SCHEMA_MAX).  A later endpoint must name the same type.
 *
 * A subscriber with AGNOCAST_TRANSIENT_LOCAL joining a topic receives, as its
 * first unreceived entries, up to depth of the newest entries still in the
 * window of publishers that are transient-local too.
 *
 *   -EINVAL  bad name, label, type name, depth, flags (POLLING or
 *            IGNORE_LOCAL on a publisher), schema_size or reserved
 *   -EPROTOTYPE the topic's type has another name or hash (TOPIC_INFO tells
 *            which)
 *   -ENOSPC  the topic has PUBLISHERS/SUBSCRIBERS_PER_TOPIC_MAX endpoints
 *   -ENFILE  the namespace has max_topics_per_namespace topics (module
 *            parameter) and this would be a new one
 *   -EMFILE  the process has max_endpoints_per_process endpoints (module
 *            parameter)
 *   -EACCES  the namespace's access policy (SET_POLICY) refuses the caller
 *            this kind of endpoint on this topic
 */
struct agnocast_add_endpoint {
	char topic[AGNOCAST_TOPIC_NAME_MAX];
	char node[AGNOCAST_NODE_NAME_MAX];
	char type_name[AGNOCAST_TYPE_NAME_MAX];
	__u64 type_hash;
	__u64 schema;
	__u32 schema_size;
	__u32 depth;
	__u32 flags;
	__u32 topic_handle;
	__u32 id;
	__u32 reserved;
};

/*
 * AGNOCAST_IOC_REMOVE_PUBLISHER, AGNOCAST_IOC_REMOVE_SUBSCRIBER
 *
 * A removed publisher's entries stay while subscribers hold them; they come
 * back for freeing through PUBLISH/RECLAIM of the same process.
 */
struct agnocast_remove_endpoint {
	__u32 topic_handle;
	__u32 id;
};

/*
 * AGNOCAST_IOC_PUBLISH
 *
 * in:  addr inside the caller's own pool; bytes, the message's size for the
 *      bandwidth counter; wake_ids/wake_capacity, a __u32 array for the ids of
 *      callback subscribers to notify; reclaim/reclaim_capacity, a __u64 array
 *      for addresses of the caller's entries that no one references any more.
 * out: entry_id; wake_count; reclaim_count; reclaim_pending, how many more
 *      freeable addresses wait for the next PUBLISH or RECLAIM.
 *
 * The entry joins the publisher's window of depth newest entries and every
 * current subscriber's unreceived list; a subscriber over its depth loses its
 * oldest unreceived entry, counted as dropped.
 *
 * All or nothing: every error is returned before the entry is published.
 * wake_ids (its first min(wake_capacity, SUBSCRIBERS_PER_TOPIC_MAX) slots),
 * reclaim (its first min(reclaim_capacity, AGNOCAST_RECLAIM_BATCH) slots) and
 * the argument itself are checked writable first; an unwritable one is
 * -EFAULT with nothing published and nothing reclaimed.  Once published, the
 * call returns 0 (see "Answers are staged" above).  At most
 * AGNOCAST_RECLAIM_BATCH addresses are returned per call; reclaim_pending
 * counts the rest.
 *
 * flags (services build on them):
 *   AGNOCAST_PUBLISH_TO_ONE  only the subscriber to_subscriber gets the
 *            entry (a response to the one client that asked); wake_capacity
 *            1 is enough.  Not on a transient-local publisher, whose window
 *            late subscribers would get.
 *   AGNOCAST_PUBLISH_NO_DROP the entry is refused rather than dropping a
 *            subscriber's oldest unreceived entry, and refused when no
 *            subscriber would get it (a request nobody will answer).
 * Without flags to_subscriber must be 0.
 *
 *   -EFAULT  addr is outside the caller's pool
 *   -ENOBUFS wake_capacity is below the topic's subscriber count
 *   -EBUSY   the caller's pool is not attached yet
 *   -EINVAL  also: unknown flag, to_subscriber without TO_ONE, TO_ONE on a
 *            transient-local publisher
 *   -ENXIO   TO_ONE: to_subscriber is not a subscriber of the topic that
 *            takes the publisher's entries (gone, or ignoring its process)
 *   -EAGAIN  NO_DROP: a subscriber that would get the entry has depth
 *            unreceived entries
 *   -EPIPE   NO_DROP: no subscriber would get the entry
 */
#define AGNOCAST_PUBLISH_TO_ONE (1U << 0)
#define AGNOCAST_PUBLISH_NO_DROP (1U << 1)

struct agnocast_publish {
	__u32 topic_handle;
	__u32 publisher_id;
	__u64 addr;
	__u64 bytes;
	__u64 wake_ids;
	__u64 reclaim;
	__u32 wake_capacity;
	__u32 reclaim_capacity;
	__u64 entry_id;
	__u32 wake_count;
	__u32 reclaim_count;
	__u32 reclaim_pending;
	__u32 flags;		/* AGNOCAST_PUBLISH_* */
	__u32 to_subscriber;
	__u32 reserved;
};

/* Most reclaimable addresses one PUBLISH or RECLAIM returns. */
#define AGNOCAST_RECLAIM_BATCH 32

/*
 * AGNOCAST_IOC_RECLAIM: only the reclaim part of PUBLISH.
 */
struct agnocast_reclaim {
	__u64 reclaim;
	__u32 reclaim_capacity;
	__u32 reclaim_count;
	__u32 reclaim_pending;
	__u32 reserved;
};

/* One received entry. */
struct agnocast_entry {
	__u64 entry_id;
	__u64 addr;
	__u32 publisher_id;
	__u32 reserved;
};

/*
 * A publisher pool the caller has not been given yet: fd is a new read-only
 * O_CLOEXEC descriptor of it, to be mapped PROT_READ, MAP_SHARED at addr.
 * The kernel hands each pool to a process once.
 */
struct agnocast_pool {
	__u64 addr;
	__u64 size;
	__s32 fd;
	__s32 pid;
};

/* Most entry ids one RELEASE, or the release list of one RECEIVE, names. */
#define AGNOCAST_RELEASE_MAX 256
/* Most entries and pools one RECEIVE returns (remaining counts the rest). */
#define AGNOCAST_RECEIVE_ENTRIES_MAX 256
#define AGNOCAST_RECEIVE_POOLS_MAX 8
/*
 * A RECEIVE of at most this many entries that releases at most as many, and
 * a RELEASE of at most as many, allocate nothing in the kernel: the batch a
 * subscriber should ask for.
 */
#define AGNOCAST_RECEIVE_BATCH 8

/*
 * AGNOCAST_IOC_RECEIVE (callback subscribers)
 *
 * in:  entries/entry_capacity, pools/pool_capacity (arrays of the structs
 *      above); release_ids/release_count, a __u64 array of entry ids the
 *      subscriber holds and drops first, as RELEASE would (release_count 0:
 *      none), so that a subscriber's steady state needs no RELEASE call.
 * out: up to entry_capacity (at most RECEIVE_ENTRIES_MAX) unreceived
 *      entries, oldest first, now held by the subscriber until released; the
 *      pools they live in that the caller has not been given (at most
 *      pool_capacity, at most RECEIVE_POOLS_MAX: receiving stops before an
 *      entry whose pool does not fit); remaining, how many unreceived entries
 *      are left.
 *
 * The releases and the receive are one: any error leaves every listed entry
 * held and receives nothing.
 *
 *   -EINVAL  entry_capacity or pool_capacity is zero, release_count is over
 *            AGNOCAST_RELEASE_MAX
 *   -ENOENT  also: a listed id is not held by the subscriber (or listed twice)
 *   -EDQUOT  unreceived entries wait but the subscriber holds
 *            max_held_per_subscriber entries (module parameter) even after
 *            the releases: release some first
 */
struct agnocast_receive {
	__u32 topic_handle;
	__u32 subscriber_id;
	__u64 entries;
	__u64 pools;
	__u32 entry_capacity;
	__u32 pool_capacity;
	__u32 entry_count;
	__u32 pool_count;
	__u32 remaining;
	__u32 release_count;
	__u64 release_ids;
};

/*
 * AGNOCAST_IOC_TAKE (polling subscribers)
 *
 * in:  flags, none defined: must be 0.
 * out: the newest unreceived entry, held until RELEASE (entry_count 1), or
 *      nothing (entry_count 0).  Older unreceived entries are passed over.
 *      pool is filled (pool_count 1) when the caller has not been given it.
 *
 *   -EDQUOT  as for RECEIVE
 *   -EAGAIN  the newest entry moved to a pool not yet given four times over
 *            while its pool was being installed (publishers restarting
 *            faster than the call); try again
 */
struct agnocast_take {
	__u32 topic_handle;
	__u32 subscriber_id;
	struct agnocast_entry entry;
	struct agnocast_pool pool;
	__u32 entry_count;
	__u32 pool_count;
	__u32 flags;
	__u32 reserved;
};

/*
 * AGNOCAST_IOC_RELEASE: the subscriber drops its references to the count
 * entry ids at entry_ids (1..AGNOCAST_RELEASE_MAX), all or none.
 *
 *   -EINVAL  count is 0 or over AGNOCAST_RELEASE_MAX, flags is not 0
 *   -ENOENT  the subscriber does not hold one of them (or it is listed
 *            twice); none is released
 */
struct agnocast_release {
	__u32 topic_handle;
	__u32 subscriber_id;
	__u64 entry_ids;
	__u32 count;
	__u32 flags;
};

/*
 * AGNOCAST_IOC_SHED: the caller's pool needs memory.  Every entry of the
 * caller's pool that has left its publisher's depth window and is kept only
 * because subscribers have not received it yet is taken from those
 * subscribers (counted in their dropped); entries a subscriber holds are
 * never taken.  Entries no one references any more become reclaimable:
 * out: shed, the number of entries taken from subscribers; reclaimable, the
 * number now waiting for RECLAIM (this call's and earlier ones).
 */
struct agnocast_shed {
	__u32 shed;
	__u32 reclaimable;
};

/*
 * Topic access policy of an IPC namespace, checked at ADD_PUBLISHER and
 * ADD_SUBSCRIBER (-EACCES).  Without a policy everyone who can open the
 * device read-write may create endpoints.
 *
 * A rule matches a topic by prefix and match kind: EXACT, the topic equals
 * prefix; CHILDREN, the topic is prefix + "/" + one more level (pattern
 * "prefix/ *" without the space); DESCENDANTS, the topic is prefix + "/" +
 * any number of levels ("prefix/ **"; an empty prefix matches every topic).
 * The first matching rule decides; a rule without AGNOCAST_RULE_PUBLISH
 * (SUBSCRIBE) leaves that direction to the default.  A listed direction is
 * allowed when one of its principals matches the caller's filesystem uid or
 * any of its groups.  No rule matching: the default decides.
 */
#define AGNOCAST_POLICY_RULES_MAX 256
#define AGNOCAST_POLICY_PRINCIPALS_MAX 4096

#define AGNOCAST_MATCH_EXACT 0
#define AGNOCAST_MATCH_CHILDREN 1
#define AGNOCAST_MATCH_DESCENDANTS 2

#define AGNOCAST_PRINCIPAL_ANYONE 0
#define AGNOCAST_PRINCIPAL_USER 1
#define AGNOCAST_PRINCIPAL_GROUP 2

/* Rule flags: which directions the rule lists principals for. */
#define AGNOCAST_RULE_PUBLISH (1U << 0)
#define AGNOCAST_RULE_SUBSCRIBE (1U << 1)

/* Policy flags. */
#define AGNOCAST_POLICY_PRESENT (1U << 0)	/* a policy is in force */
#define AGNOCAST_POLICY_DEFAULT_DENY (1U << 1)

struct agnocast_principal {
	__u32 kind;
	__u32 id;	/* uid or gid in the caller's user namespace */
};

/* Principals of a rule: publish ones first, then subscribe ones. */
struct agnocast_policy_rule {
	char prefix[AGNOCAST_TOPIC_NAME_MAX];
	__u32 match;
	__u32 flags;
	__u32 first_principal;	/* index into the policy's principals */
	__u32 publish_count;
	__u32 subscribe_count;
	__u32 reserved;
};

/*
 * AGNOCAST_IOC_SET_POLICY: replace the namespace's policy (flags without
 * AGNOCAST_POLICY_PRESENT removes it).  Existing endpoints stay.  Needs
 * CAP_SYS_ADMIN over the IPC namespace's user namespace.
 *
 *   -EPERM   the caller lacks that capability
 *   -EINVAL  a count over its _MAX, a prefix that is not "" or a valid topic
 *            name, an unknown match/kind/flag, principals out of range, or an
 *            id that does not map into the caller's user namespace
 *
 * AGNOCAST_IOC_GET_POLICY: anyone.  in: flags 0; capacities in rule_count
 * and principal_count (arrays may be 0 with capacity 0).  out: the policy's
 * flags and its total counts; the arrays are filled when they fit, else
 * -ENOSPC (call again with the totals).
 */
struct agnocast_policy {
	__u32 flags;
	__u32 rule_count;
	__u32 principal_count;
	__u32 reserved;
	__u64 rules;
	__u64 principals;
};

/* Introspection: callable without registering. */

struct agnocast_topic_summary {
	char name[AGNOCAST_TOPIC_NAME_MAX];
	char type_name[AGNOCAST_TYPE_NAME_MAX];
	__u64 type_hash;
	__u32 publishers;
	__u32 subscribers;
};

/*
 * AGNOCAST_IOC_LIST_TOPICS
 *
 * out: total, the number of topics with at least one endpoint; the first
 *      min(total, capacity) of them, in name order, in topics[].
 */
struct agnocast_list_topics {
	__u64 topics;
	__u32 capacity;
	__u32 total;
	__u32 flags;		/* none defined: must be 0 */
	__u32 reserved;
};

/* uid: the owning process's effective uid when it registered. */
struct agnocast_publisher_info {
	char node[AGNOCAST_NODE_NAME_MAX];
	__u32 id;
	__s32 pid;
	__u32 depth;
	__u32 flags;
	__u64 published;
	__u64 published_bytes;
	__u32 window;
	__u32 uid;
};

struct agnocast_subscriber_info {
	char node[AGNOCAST_NODE_NAME_MAX];
	__u32 id;
	__s32 pid;
	__u32 depth;
	__u32 flags;
	__u32 unreceived;
	__u32 held;
	__u64 received;
	__u64 dropped;
	__u32 uid;
	__u32 reserved;
};

/*
 * AGNOCAST_IOC_TOPIC_INFO
 *
 * in:  name; publishers/subscribers arrays and their capacities.
 * out: totals and the first min(total, capacity) endpoints by id; entries,
 *      the number of live entries of the topic; its type and schema size.
 *
 *   -ENOENT  no topic of that name has an endpoint
 */
struct agnocast_topic_info {
	char name[AGNOCAST_TOPIC_NAME_MAX];
	char type_name[AGNOCAST_TYPE_NAME_MAX];
	__u64 type_hash;
	__u64 publishers;
	__u64 subscribers;
	__u32 publisher_capacity;
	__u32 subscriber_capacity;
	__u32 publisher_total;
	__u32 subscriber_total;
	__u32 entries;
	__u32 schema_size;
};

/*
 * AGNOCAST_IOC_TOPIC_SCHEMA: the schema of a topic.
 *
 * in:  name; schema/capacity, a buffer.  out: size, the schema's size; the
 *      schema in the buffer.
 *
 *   -ENOENT  no topic of that name has an endpoint
 *   -ENODATA the topic has no schema
 *   -ENOSPC  capacity is below size (size is set)
 */
struct agnocast_topic_schema {
	char name[AGNOCAST_TOPIC_NAME_MAX];
	__u64 schema;
	__u32 capacity;
	__u32 size;
};

struct agnocast_process_info {
	__s32 pid;
	__u32 publishers;
	__u32 subscribers;
	__u32 pools_mapped;
	__u64 pool_addr;
	__u64 pool_size;
};

/*
 * AGNOCAST_IOC_LIST_PROCESSES: registered processes of the caller's
 * namespace, by pid.
 */
struct agnocast_list_processes {
	__u64 processes;
	__u32 capacity;
	__u32 total;
	__u32 flags;		/* none defined: must be 0 */
	__u32 reserved;
};

/*
 * AGNOCAST_IOC_NOTIFY_FAILED: the caller's publisher publisher_id of the
 * topic topic_handle could not send the notification a PUBLISH listed
 * subscriber_id for (its queue could not be opened, or the send failed other
 * than for a full queue).  Unless the subscriber has looked since, it is
 * listed again by the next PUBLISH and its process's wake eventfd is
 * signalled (AGNOCAST_WAKE_ONCE).
 *
 *   -ENOENT  no such publisher, or the subscriber is gone (nothing waits
 *            for it)
 *   -EPERM   the publisher is another process's
 *   -ESRCH   the caller is not registered
 *   -EINVAL  reserved is not 0
 */
struct agnocast_notify_failed {
	__u32 topic_handle;
	__u32 publisher_id;
	__u32 subscriber_id;
	__u32 reserved;
};

#define AGNOCAST_IOC_MAGIC 0xAC

#define AGNOCAST_IOC_GET_VERSION _IOR(AGNOCAST_IOC_MAGIC, 0, struct agnocast_version)
#define AGNOCAST_IOC_REGISTER_PROCESS \
	_IOWR(AGNOCAST_IOC_MAGIC, 1, struct agnocast_register_process)
#define AGNOCAST_IOC_UNREGISTER_PROCESS _IO(AGNOCAST_IOC_MAGIC, 2)
#define AGNOCAST_IOC_ADD_PUBLISHER _IOWR(AGNOCAST_IOC_MAGIC, 3, struct agnocast_add_endpoint)
#define AGNOCAST_IOC_REMOVE_PUBLISHER _IOW(AGNOCAST_IOC_MAGIC, 4, struct agnocast_remove_endpoint)
#define AGNOCAST_IOC_ADD_SUBSCRIBER _IOWR(AGNOCAST_IOC_MAGIC, 5, struct agnocast_add_endpoint)
#define AGNOCAST_IOC_REMOVE_SUBSCRIBER \
	_IOW(AGNOCAST_IOC_MAGIC, 6, struct agnocast_remove_endpoint)
#define AGNOCAST_IOC_PUBLISH _IOWR(AGNOCAST_IOC_MAGIC, 7, struct agnocast_publish)
#define AGNOCAST_IOC_RECLAIM _IOWR(AGNOCAST_IOC_MAGIC, 8, struct agnocast_reclaim)
#define AGNOCAST_IOC_RECEIVE _IOWR(AGNOCAST_IOC_MAGIC, 9, struct agnocast_receive)
#define AGNOCAST_IOC_TAKE _IOWR(AGNOCAST_IOC_MAGIC, 10, struct agnocast_take)
#define AGNOCAST_IOC_RELEASE _IOW(AGNOCAST_IOC_MAGIC, 11, struct agnocast_release)
#define AGNOCAST_IOC_LIST_TOPICS _IOWR(AGNOCAST_IOC_MAGIC, 12, struct agnocast_list_topics)
#define AGNOCAST_IOC_TOPIC_INFO _IOWR(AGNOCAST_IOC_MAGIC, 13, struct agnocast_topic_info)
#define AGNOCAST_IOC_LIST_PROCESSES \
	_IOWR(AGNOCAST_IOC_MAGIC, 14, struct agnocast_list_processes)
#define AGNOCAST_IOC_SHED _IOR(AGNOCAST_IOC_MAGIC, 15, struct agnocast_shed)
#define AGNOCAST_IOC_SET_POLICY _IOW(AGNOCAST_IOC_MAGIC, 16, struct agnocast_policy)
#define AGNOCAST_IOC_GET_POLICY _IOWR(AGNOCAST_IOC_MAGIC, 17, struct agnocast_policy)
#define AGNOCAST_IOC_TOPIC_SCHEMA _IOWR(AGNOCAST_IOC_MAGIC, 18, struct agnocast_topic_schema)
#define AGNOCAST_IOC_NOTIFY_FAILED _IOW(AGNOCAST_IOC_MAGIC, 19, struct agnocast_notify_failed)

/*
 * Exit records: read() on /dev/agnocast returns whole records, oldest first,
 * of the caller's namespace; poll() reports POLLIN while any wait.  Records
 * stay queued until read, so a restarted daemon misses none.  Past
 * AGNOCAST_EXIT_RECORDS_MAX the oldest are discarded, and the next read
 * starts with one AGNOCAST_EXIT_LOST record whose subscriber_id is how many
 * were discarded: the reader must then look for leftovers itself.  Reading needs
 * a descriptor opened with CAP_SYS_ADMIN in the user namespace of the IPC
 * namespace it was opened in (-EPERM otherwise; decided at open, like a
 * file's permissions, and valid for whoever holds the descriptor); it reads
 * that namespace's records.  A buffer smaller than one record is -EINVAL; with none waiting, read blocks
 * or, with O_NONBLOCK, fails with -EAGAIN.
 *
 * A dead process yields one AGNOCAST_EXIT_PROCESS record, preceded by one
 * AGNOCAST_EXIT_QUEUE record per callback subscriber it owned, naming the
 * notification queue's topic and subscriber id.
 */
#define AGNOCAST_EXIT_RECORDS_MAX 4096

#define AGNOCAST_EXIT_PROCESS 1
#define AGNOCAST_EXIT_QUEUE 2
#define AGNOCAST_EXIT_LOST 3

struct agnocast_exit_record {
	__u32 kind;
	__s32 pid;
	__u32 subscriber_id;
	__u32 reserved;
	char topic[AGNOCAST_TOPIC_NAME_MAX];
};

#endif /* _UAPI_LINUX_AGNOCAST_H */
