/* SPDX-License-Identifier: GPL-2.0 */
/*
 * agnocast: state shared between the module's files.
 *
 * Locking, outermost first.  Every field below says which lock protects it.
 *
 *   agnocast_ns_list_lock (mutex)       the list of namespace states
 *   agnocast_ns.exit_read_lock (mutex)  serialises readers of exit records
 *   agnocast_ns.lock (rw_semaphore)     the namespace's structure.  Taken for
 *       write (killably) by what changes it: registering and tearing down
 *       processes, adding and removing endpoints (and so topics), attaching
 *       and freeing pools, setting the policy.  Taken for read (killably) by
 *       everything else: the data path (PUBLISH, RECLAIM, RECEIVE, TAKE,
 *       RELEASE, SHED) and introspection.  Holding it for write excludes
 *       every other call of the namespace, so nothing below is then needed.
 *   agnocast_topic.lock (mutex)         one topic's entries, windows,
 *       subscribers' rings and held entries, and counters: the data path of
 *       different topics never contends.  Never two at once.
 *   agnocast_proc.reclaim_lock (spinlock) a process's reclaim list, which
 *       every topic's data path may add to
 *   agnocast_ns.exit_lock (spinlock)    the namespace's exit record list
 *   agnocast_proc_table_lock (raw spinlock) changes to the tgid table,
 *       also taken from the exit and exec tracepoints; lookups use RCU
 *
 * No user copy and no descriptor install happens under agnocast_ns.lock or
 * below: arguments are copied in before, answers staged and copied out
 * after, descriptors installed in between with no lock held.
 */
#ifndef _AGNOCAST_INTERNAL_H
#define _AGNOCAST_INTERNAL_H

#include <linux/hashtable.h>
#include <linux/kernel.h>
#include <linux/mm.h>
#include <linux/uaccess.h>
#include <linux/idr.h>
#include <linux/list.h>
#include <linux/mutex.h>
#include <linux/rwsem.h>
#include <linux/spinlock.h>
#include <linux/pid.h>
#include <linux/jiffies.h>
#include <linux/timer.h>
#include <linux/slab.h>
#include <linux/types.h>
#include <linux/uidgid.h>
#include <linux/version.h>
#include <linux/wait.h>
#include <linux/workqueue.h>
#include <linux/xarray.h>

#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 12, 0)
#include <linux/unaligned.h>
#else
#include <asm/unaligned.h>
#endif

#include "agnocast.h"

/* Endpoints a process finds again without a lookup (a power of two). */
#define AGNOCAST_RECENT_ENDPOINTS 8

/* Unreferenced id spaces kept so that topic_local_ids are not reused soon. */
#define AGNOCAST_DORMANT_ID_SPACES_MAX 1024

struct ipc_namespace;
struct file;
struct pid;
struct super_block;
struct vfsmount;
struct agnocast_policy_state;

extern unsigned long agnocast_pool_size;
extern unsigned int agnocast_pool_count;
extern unsigned long agnocast_pool_base;
extern unsigned int agnocast_max_endpoints_per_process;
extern unsigned int agnocast_max_held_per_subscriber;
extern unsigned int agnocast_max_topics_per_namespace;

/* State of one IPC namespace. */
struct agnocast_ns {
	struct list_head list_node;	/* protected by agnocast_ns_list_lock */
	/* Users: open files, in-flight calls, teardown work.  Reaches 0 only
	 * under agnocast_ns_list_lock, and only then may the state be freed.
	 */
	atomic_t users;
	/*
	 * The key: the superblock of the namespace's internal mqueue mount,
	 * kept alive (and so never reused) by our reference on the mount.
	 * Its s_fs_info is cleared when the namespace dies.
	 */
	struct vfsmount *mq_mnt;
	struct super_block *mq_sb;

	struct mutex exit_read_lock;	/* serialises readers of exit records */
	struct rw_semaphore lock;
	/* Everything below is protected by @lock (written under it for write). */
	unsigned long *slot_map;	/* pool_count bits: slot in use */
	struct agnocast_mempool **slots;	/* pool_count entries */
	struct list_head orphan_pools;	/* pools whose owner is gone */
	bool collect_pools;		/* set under @lock for read: one may be free */
	struct list_head procs;
	unsigned int nr_procs;
	DECLARE_HASHTABLE(topics, 8);
	struct idr topic_handles;
	unsigned int nr_topics;
	DECLARE_HASHTABLE(id_spaces, 8);
	struct list_head dormant_id_spaces; /* oldest first */
	unsigned int nr_dormant_id_spaces;
	spinlock_t exit_lock;
	/* Protected by @exit_lock. */
	struct list_head exit_records;	/* oldest first */
	unsigned int nr_exit_records;	/* read without @lock by poll */
	u64 exit_records_lost;		/* discarded, not yet reported; ditto */
	u64 exit_records_seq;
	wait_queue_head_t exit_wait;
	struct agnocast_policy_state *policy;	/* NULL: everyone may; ns->lock */
};

/* A publisher's shared-memory pool, occupying one slot. */
struct agnocast_mempool {
	/* Written under the namespace lock for write but @entries. */
	unsigned int slot;
	u64 addr;
	u64 size;
	struct file *file;		/* read-only reopening; NULL until attached */
	struct agnocast_proc *owner;	/* NULL once the owner is gone */
	struct list_head orphan_node;	/* on ns->orphan_pools once it is */
	struct pid *owner_pid;
	atomic_long_t entries;		/* live entries inside the pool */
};

/* A registered process. */
struct agnocast_proc {
	struct hlist_node table_node;	/* written under agnocast_proc_table_lock */
	struct rcu_head rcu;
	bool dying;			/* written under agnocast_proc_table_lock */
	pid_t tgid;			/* init-namespace number; the table key */
	u64 exec_id;
	kuid_t uid;			/* effective uid at registration */
	struct pid *pid;
	struct agnocast_ns *ns;
	struct work_struct teardown_work;
	/* Queued when the process dies; NULL after. Protected by ns->lock. */
	struct agnocast_exit_record_node *exit_record;

	/* Written under ns->lock for write. */
	struct list_head ns_node;
	struct agnocast_mempool *pool;
	struct list_head publishers;	/* of agnocast_endpoint.proc_node */
	struct list_head subscribers;	/* ditto */
	unsigned int nr_publishers;
	unsigned int nr_subscribers;
	/* pool_count bits: live pools handed over; atomic bit operations. */
	unsigned long *given;
	spinlock_t reclaim_lock;
	/* Protected by @reclaim_lock. */
	struct list_head reclaim;	/* freed entries of this process's pool */
	unsigned int nr_reclaim;
	/*
	 * An entry whose address a PUBLISH or RECLAIM returned, kept for the
	 * process's next PUBLISH instead of freed (xchg/cmpxchg).
	 */
	struct agnocast_topic_entry *spare_entry;
	/*
	 * The process's endpoints it named last, by (topic handle, id): the
	 * data path finds them without walking two trees.  Stored under the
	 * namespace lock held for read (racing stores are equally right),
	 * cleared under it held for write when the endpoint goes.
	 */
	struct agnocast_endpoint *recent_endpoints[AGNOCAST_RECENT_ENDPOINTS];
	/* Signalled when a notification to a subscriber of it may be lost. */
	struct eventfd_ctx *wake_eventfd;
};

/* Names equal after mangling share one topic_local_id counter. */
struct agnocast_id_space {
	struct hlist_node hash_node;
	struct list_head dormant_node;	/* on ns->dormant_id_spaces iff !topics */
	unsigned int topics;
	u32 next_id;
	char mangled[AGNOCAST_TOPIC_NAME_MAX];
};

/* Written under ns->lock for write, but what @lock protects. */
struct agnocast_topic {
	struct hlist_node hash_node;
	struct agnocast_ns *ns;
	struct agnocast_id_space *ids;
	u32 handle;
	struct xarray endpoints;	/* id -> struct agnocast_endpoint */
	struct list_head publishers;	/* by id */
	struct list_head subscribers;	/* by id */
	unsigned int nr_publishers;
	unsigned int nr_subscribers;
	unsigned int nr_callback_subscribers;
	struct mutex lock;
	/* Protected by @lock, with the windows, rings and held entries. */
	struct list_head entries;	/* by id */
	unsigned int nr_entries;
	u64 next_entry_id;
	/* The type, fixed by the endpoint that created the topic. */
	u64 type_hash;
	void *schema;			/* from the first endpoint that had one */
	u32 schema_size;
	char type_name[AGNOCAST_TYPE_NAME_MAX];
	char name[AGNOCAST_TOPIC_NAME_MAX];
};

/*
 * What publishers and subscribers share: found by id in topic->endpoints.
 * The head is written under ns->lock for write; the rest of a publisher and
 * a subscriber under topic->lock.
 */
struct agnocast_endpoint {
	struct list_head topic_node;	/* on topic->publishers or ->subscribers */
	struct list_head proc_node;	/* on proc->publishers or ->subscribers */
	struct agnocast_topic *topic;
	struct agnocast_proc *proc;
	bool publisher;
	u32 id;
	u32 depth;
	u32 flags;
	char node[AGNOCAST_NODE_NAME_MAX];
};

struct agnocast_publisher {
	struct agnocast_endpoint ep;
	struct list_head window;	/* oldest first */
	u32 window_len;
	u64 published;
	u64 published_bytes;
};

struct agnocast_subscriber {
	struct agnocast_endpoint ep;
	/* Ring of ep.depth unreceived entries, oldest at @head. */
	struct agnocast_topic_entry **unreceived;
	u32 head;
	u32 nr_unreceived;
	/* Held entries, by id; room for @held_capacity. */
	struct agnocast_topic_entry **held;
	u32 nr_held;
	u32 held_capacity;
	u64 received;
	u64 dropped;
	/*
	 * Callback subscribers: listed by a PUBLISH since the last RECEIVE or
	 * TAKE (a wake-once one is listed again only when this is false), when
	 * first, by which process (compared, never followed); and what breaks
	 * that promise when it is not kept (agnocast_wake.c).
	 */
	bool notified;
	unsigned long notified_at;
	struct agnocast_proc *notifier;
	struct timer_list watchdog;
	/* Callback subscribers: queued when the process dies (ns->lock). */
	struct agnocast_exit_record_node *exit_record;
};

/* AGNOCAST_IGNORE_LOCAL: the subscriber never gets its own process's entries. */
static inline bool agnocast_sub_ignores(const struct agnocast_endpoint *sub,
					const struct agnocast_publisher *pub)
{
	return (sub->flags & AGNOCAST_IGNORE_LOCAL) && sub->proc == pub->ep.proc;
}

/* One published message of a topic; the UAPI's entry.  topic->lock. */
struct agnocast_topic_entry {
	/* On topic->entries while live, on the owner's reclaim list after. */
	struct list_head node;
	struct list_head window_node;	/* valid while @publisher is set */
	struct agnocast_topic *topic;
	struct agnocast_publisher *publisher; /* NULL once out of the window */
	struct agnocast_mempool *pool;
	u64 id;
	u64 addr;
	u32 publisher_id;
	/* One while in the window, plus one per subscriber reference. */
	unsigned int refs;
};

/* Exit records: allocated with what they describe, queued at death. */
struct agnocast_exit_record_node {
	struct list_head node;
	u32 kind;
	u32 subscriber_id;
	u64 seq;			/* order of queueing, from 1 */
	struct pid *pid;
	char topic[AGNOCAST_TOPIC_NAME_MAX];
};

static inline struct agnocast_exit_record_node *agnocast_exit_record_alloc(void)
{
	return kzalloc(sizeof(struct agnocast_exit_record_node), GFP_KERNEL_ACCOUNT);
}

static inline void agnocast_exit_record_free(struct agnocast_exit_record_node *rec)
{
	if (!rec)
		return;
	put_pid(rec->pid);
	kfree(rec);
}

/* An open /dev/agnocast. */
struct agnocast_file {
	struct agnocast_ns *ns;		/* the opener's namespace, with a user reference */
	bool may_read_exit_records;	/* decided at open */
};

/* The calling process's view, valid between agnocast_enter_*() and agnocast_leave(). */
struct agnocast_ctx {
	struct agnocast_ns *ns;
	struct agnocast_proc *proc;	/* NULL if not registered */
	bool ns_from_file;		/* ns is the open file's: no reference of our own */
	bool write;			/* ns->lock is held for write */
};

/* agnocast_ns.c */
int agnocast_ns_key_matches(const struct agnocast_ns *ns);
bool agnocast_ns_dead(const struct agnocast_ns *ns);
struct agnocast_ns *agnocast_ns_get_current(void);
void agnocast_ns_get(struct agnocast_ns *ns);
void agnocast_ns_put(struct agnocast_ns *ns);
void agnocast_ns_init(void);
void agnocast_ns_exit(void);
void agnocast_exit_record_queue(struct agnocast_ns *ns, struct agnocast_exit_record_node *rec,
				u32 kind, struct pid *pid, u32 subscriber_id, const char *topic);
void agnocast_exit_records_wake(struct agnocast_ns *ns);
bool agnocast_exit_records_waiting(const struct agnocast_ns *ns);
ssize_t agnocast_read_exit_records(struct agnocast_ns *ns, char __user *buf,
				   size_t count, bool nonblock);

/* agnocast_process.c: registered processes, exit detection, teardown. */
int agnocast_process_init(void);
void agnocast_process_exit(void);
void agnocast_proc_settle(void);
int agnocast_proc_find_current(struct agnocast_ns *ns, struct agnocast_proc **out);
struct agnocast_proc *agnocast_proc_create(struct agnocast_ns *ns);
void agnocast_proc_unregister(struct agnocast_proc *proc);

/* agnocast_policy.c: the namespace's topic access policy. */
/* A policy in UAPI form, to copy out. */
struct agnocast_policy_copy {
	u32 flags;
	u32 nr_rules;
	u32 nr_principals;
	struct agnocast_policy_rule *rules;
	struct agnocast_principal *principals;
};

bool agnocast_policy_arg_valid(const struct agnocast_policy *arg);
struct agnocast_policy_state *agnocast_policy_build(const struct agnocast_policy *arg,
						    const struct agnocast_policy_rule *rules,
						    const struct agnocast_principal *principals);
int agnocast_policy_check(const struct agnocast_ns *ns, const char *topic, bool publisher);
void agnocast_policy_free(struct agnocast_policy_state *policy);
int agnocast_policy_snapshot(const struct agnocast_policy_state *policy,
			     struct agnocast_policy_copy *copy);
void agnocast_policy_copy_free(struct agnocast_policy_copy *copy);

/* agnocast_pool.c */
struct agnocast_mempool *agnocast_pool_reserve(struct agnocast_ns *ns,
					    struct agnocast_proc *owner);
int agnocast_pool_attach(struct agnocast_mempool *pool, int fd);
void agnocast_pool_orphan(struct agnocast_ns *ns, struct agnocast_mempool *pool);
void agnocast_pools_collect(struct agnocast_ns *ns);
bool agnocast_pool_needs_giving(const struct agnocast_proc *proc,
				const struct agnocast_mempool *pool);
void agnocast_pool_describe(struct agnocast_mempool *pool, struct agnocast_pool *out);
void agnocast_pool_mark_given(struct agnocast_proc *proc, const struct agnocast_pool *granted,
			      struct file *file);
void agnocast_pool_drop_given(struct agnocast_proc *proc);

/* agnocast_wake.c: the promise a PUBLISH's listing makes, and breaking it. */
#define AGNOCAST_WAKE_WATCHDOG_JIFFIES msecs_to_jiffies(AGNOCAST_WAKE_WATCHDOG_MS)
void agnocast_wake_break(struct agnocast_subscriber *sub);
void agnocast_wake_sub_init(struct agnocast_subscriber *sub);
void agnocast_wake_sub_shutdown(struct agnocast_subscriber *sub);
void agnocast_wake_publisher_gone(struct agnocast_proc *proc);
void agnocast_wake_set_eventfd(struct agnocast_proc *proc, struct eventfd_ctx *wake);
void agnocast_wake_put_eventfd(struct agnocast_proc *proc);

/*
 * A PUBLISH by @notifier lists @sub (topic->lock held): the watchdog checks
 * that it looks within AGNOCAST_WAKE_WATCHDOG_MS of the first listing since
 * it last looked.  Arming costs a timer update at most once per wake-up,
 * none while the timer of an earlier one is still pending.
 */
static inline void agnocast_wake_promise(struct agnocast_subscriber *sub,
					 struct agnocast_proc *notifier)
{
	sub->notifier = notifier;
	if (sub->notified)
		return;
	WRITE_ONCE(sub->notified_at, jiffies);
	WRITE_ONCE(sub->notified, true);
	/* The unit tests' subscribers have no watchdog. */
	if (sub->watchdog.function && !timer_pending(&sub->watchdog))
		mod_timer(&sub->watchdog, sub->notified_at + AGNOCAST_WAKE_WATCHDOG_JIFFIES);
}

/* agnocast_entry.c: the entry engine; no user copies, topic->lock held. */
int agnocast_entry_init(void);
void agnocast_entry_exit(void);
struct agnocast_topic_entry *agnocast_entry_alloc(void);
void agnocast_entry_free(struct agnocast_topic_entry *entry);
int agnocast_entry_admits(struct agnocast_publisher *pub, struct agnocast_subscriber *to);
u32 agnocast_entry_publish(struct agnocast_publisher *pub, struct agnocast_subscriber *to,
			   struct agnocast_topic_entry *entry, struct agnocast_mempool *pool,
			   u64 addr, u64 bytes, u32 *wake);
void agnocast_publisher_drop_window(struct agnocast_publisher *pub);
struct agnocast_topic_entry *agnocast_sub_unreceived(const struct agnocast_subscriber *sub,
						     u32 i);
void agnocast_sub_fill_transient(struct agnocast_subscriber *sub);
void agnocast_sub_drop_entries(struct agnocast_subscriber *sub);
int agnocast_sub_receivable(struct agnocast_subscriber *sub, u32 release_count, u32 max, u32 *n);
int agnocast_sub_takeable(struct agnocast_subscriber *sub);
int agnocast_sub_reserve_held(struct agnocast_subscriber *sub, u32 n);
void agnocast_sub_receive(struct agnocast_subscriber *sub, struct agnocast_entry *out, u32 n);
void agnocast_sub_take_newest(struct agnocast_subscriber *sub, struct agnocast_entry *out);
int agnocast_sub_release(struct agnocast_subscriber *sub, const u64 *ids, u32 n);
u32 agnocast_proc_shed(struct agnocast_proc *proc, u32 *reclaimable);
u32 agnocast_reclaim_take(struct agnocast_proc *proc, u64 *addrs, u32 max, u32 *pending);
struct agnocast_topic_entry *agnocast_proc_entry_alloc(struct agnocast_proc *proc);
void agnocast_reclaim_return(struct agnocast_proc *proc, const u64 *addrs, u32 n);
void agnocast_proc_drop_reclaim(struct agnocast_proc *proc);

/* agnocast_topic.c: topics, id spaces, endpoints. */
bool agnocast_topic_name_valid(const char *name);
bool agnocast_endpoint_args_valid(const struct agnocast_add_endpoint *arg, bool publisher);
struct agnocast_topic *agnocast_topic_find(struct agnocast_ns *ns, const char *name);
struct agnocast_topic *agnocast_topic_get(struct agnocast_ns *ns, const char *name);
void agnocast_topic_maybe_free(struct agnocast_topic *topic);
int agnocast_topic_type_check(struct agnocast_topic *topic,
			      const struct agnocast_add_endpoint *arg, void **schema);
struct agnocast_endpoint *agnocast_endpoint_create(struct agnocast_topic *topic,
						   struct agnocast_proc *proc,
						   const struct agnocast_add_endpoint *arg,
						   bool publisher);
void agnocast_endpoint_commit(struct agnocast_endpoint *ep);
void agnocast_endpoint_abandon(struct agnocast_endpoint *ep);
void agnocast_endpoint_destroy(struct agnocast_endpoint *ep);
int agnocast_endpoint_lookup(struct agnocast_ns *ns, struct agnocast_proc *proc, u32 handle,
			     u32 id, bool publisher, struct agnocast_endpoint **out);
void agnocast_proc_drop_endpoints(struct agnocast_proc *proc);
void agnocast_id_spaces_free(struct agnocast_ns *ns);

static inline struct agnocast_publisher *agnocast_to_publisher(struct agnocast_endpoint *ep)
{
	return container_of(ep, struct agnocast_publisher, ep);
}

static inline struct agnocast_subscriber *agnocast_to_subscriber(struct agnocast_endpoint *ep)
{
	return container_of(ep, struct agnocast_subscriber, ep);
}

/*
 * The handlers: copy in, enter, call down, leave, copy out.  Nothing below
 * them calls back up.
 */

/* agnocast_call.c: the call context and the lock each call takes. */
int agnocast_enter_read(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns);
int agnocast_enter_write(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns);
int agnocast_enter_ns_read(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns);
int agnocast_enter_ns_write(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns);
void agnocast_leave(struct agnocast_ctx *ctx);
int agnocast_unwritable(struct agnocast_ns *file_ns);

/*
 * The data path's arguments and answers are a few words each, moved here a
 * word at a time in one user-access window: copy_from_user() and
 * copy_to_user() move them a byte at a time (a string instruction, or a byte
 * loop under 64 bytes), which costs more than the call's own work.  Larger
 * ones still go through them.  @bytes is a multiple of 4; none is no access
 * at all, as with copy_from_user(), whatever the pointer.
 */
#define AGNOCAST_WORDS_MAX 256

static __always_inline int agnocast_words_in(void *to, const void __user *from, size_t bytes)
{
	size_t i;
	u64 word;
	u32 half;

	BUILD_BUG_ON(__builtin_constant_p(bytes) && bytes % sizeof(u32));
	if (!bytes)
		return 0;
	if (bytes > AGNOCAST_WORDS_MAX)
		return copy_from_user(to, from, bytes) ? -EFAULT : 0;
	if (!user_access_begin(from, bytes))
		return -EFAULT;
	for (i = 0; i + sizeof(u64) <= bytes; i += sizeof(u64)) {
		unsafe_get_user(word, (const u64 __user *)(from + i), efault);
		put_unaligned(word, (u64 *)(to + i));
	}
	if (i < bytes) {
		unsafe_get_user(half, (const u32 __user *)(from + i), efault);
		put_unaligned(half, (u32 *)(to + i));
	}
	user_access_end();
	return 0;
efault:
	user_access_end();
	return -EFAULT;
}

static __always_inline int agnocast_words_out(void __user *to, const void *from, size_t bytes)
{
	size_t i;

	BUILD_BUG_ON(__builtin_constant_p(bytes) && bytes % sizeof(u32));
	if (!bytes)
		return 0;
	if (bytes > AGNOCAST_WORDS_MAX)
		return copy_to_user(to, from, bytes) ? -EFAULT : 0;
	if (!user_access_begin(to, bytes))
		return -EFAULT;
	for (i = 0; i + sizeof(u64) <= bytes; i += sizeof(u64))
		unsafe_put_user(get_unaligned((const u64 *)(from + i)), (u64 __user *)(to + i),
				efault);
	if (i < bytes)
		unsafe_put_user(get_unaligned((const u32 *)(from + i)), (u32 __user *)(to + i),
				efault);
	user_access_end();
	return 0;
efault:
	user_access_end();
	return -EFAULT;
}

/*
 * Checks @bytes at @ubuf writable, keeping what the caller has there (on
 * every PUBLISH and RECEIVE: inline).
 */
static inline int agnocast_out_writable(u64 ubuf, size_t bytes)
{
	char __user *p = u64_to_user_ptr(ubuf);
	char __user *end = p + bytes;
	char c;

	if (!bytes)
		return 0;
	if (!user_access_begin(p, bytes))
		return -EFAULT;
	/*
	 * One byte of each page, written back with its own value: the page is
	 * writable and present, and what the caller keeps there is unchanged.
	 * Cheaper than fault_in_safe_writeable(), which walks the page tables
	 * through get_user_pages for every call.
	 */
	while (p < end) {
		unsafe_get_user(c, p, efault);
		unsafe_put_user(c, p, efault);
		p = (char __user *)PAGE_ALIGN((unsigned long)p + 1);
	}
	user_access_end();
	return 0;
efault:
	user_access_end();
	return -EFAULT;
}

/* Writes an answer after commit; a failure loses only the answer. */
static inline bool agnocast_answer_out(void __user *to, const void *from, size_t bytes)
{
	return !agnocast_words_out(to, from, bytes);
}

/* agnocast_grant.c: pools handed to a subscriber (RECEIVE, TAKE). */
struct agnocast_grants {
	struct file *files[AGNOCAST_RECEIVE_POOLS_MAX];
	struct agnocast_pool out[AGNOCAST_RECEIVE_POOLS_MAX];
	u32 count;
	u32 capacity;
	/*
	 * Installed grants no entry of the call needs any more: TAKE's grant
	 * replaced by another, or those commit withheld.  Closed and put with
	 * no lock held.
	 */
	struct file *withheld_files[AGNOCAST_RECEIVE_POOLS_MAX];
	int withheld_fds[AGNOCAST_RECEIVE_POOLS_MAX];
	u32 withheld;
};

bool agnocast_grants_readable(const struct agnocast_proc *proc,
			      const struct agnocast_grants *grants,
			      const struct agnocast_mempool *pool);
bool agnocast_grants_add(struct agnocast_grants *grants, struct agnocast_mempool *pool);
void agnocast_grants_add_over(struct agnocast_grants *grants, struct agnocast_mempool *pool);
int agnocast_grants_install(struct agnocast_grants *grants, u32 from);
void agnocast_grants_commit(struct agnocast_proc *proc, struct agnocast_grants *grants,
			    const struct agnocast_subscriber *sub, u32 first, u32 n);
void agnocast_grants_put(struct agnocast_grants *grants);
void agnocast_grants_close(struct agnocast_grants *grants);

/* agnocast_admin.c: processes and the access policy. */
int agnocast_register_process(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_unregister_process(struct agnocast_ns *file_ns);
int agnocast_set_policy(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_get_policy(struct agnocast_ns *file_ns, void __user *uarg);

/* agnocast_ioctl.c: endpoint and data-path commands. */
int agnocast_add_publisher(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_add_subscriber(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_remove_publisher(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_remove_subscriber(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_publish(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_notify_failed(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_reclaim(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_receive(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_take(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_release(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_shed(struct agnocast_ns *file_ns, void __user *uarg);

/* agnocast_introspect.c */
int agnocast_list_topics(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_topic_info(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_list_processes(struct agnocast_ns *file_ns, void __user *uarg);
int agnocast_topic_schema(struct agnocast_ns *file_ns, void __user *uarg);

#endif /* _AGNOCAST_INTERNAL_H */
