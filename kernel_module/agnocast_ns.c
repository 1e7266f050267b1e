// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: per-IPC-namespace state.
 *
 * Topics, ids, pool slots and exit records belong to the IPC namespace of the
 * calling process, like POSIX message queues.  Exit records, the list of
 * what dead processes left behind (their notification queues) read by the
 * daemon through read(), live here with the namespace that owns them.  put_ipc_ns() is not exported,
 * so no reference on the namespace is taken.  The state is keyed instead by
 * the superblock of the namespace's internal mqueue mount, on which it holds
 * a mount reference: the superblock then outlives the namespace, so no later
 * namespace can have the same key, and the kernel clears its s_fs_info when
 * the namespace dies, which tells us the state is dead.  State is freed when
 * it has no users and no processes and either is idle (no topics, no exit
 * records, no access policy) or belongs to a dead namespace, whose exit
 * records and policy nobody can use any more.  Dead states left behind by a last user from another
 * namespace are collected at the next open.
 *
 * The locking order is in agnocast_internal.h; agnocast_ns_list_lock is the
 * outermost.  agnocast_ns.users is incremented only under agnocast_ns_list_lock (or while
 * already nonzero by the holder of a user) and drops to 0 only under it, so a
 * state seen with users == 0 under agnocast_ns_list_lock has no lock holder
 * and may be read and freed without agnocast_ns.lock.  An ioctl on a file
 * opened in the caller's namespace borrows the file's user reference (held
 * until release, which cannot run during the ioctl) instead of taking one.
 */
#include <linux/bitmap.h>
#include <linux/capability.h>
#include <linux/debugfs.h>
#include <linux/fs.h>
#include <linux/ipc_namespace.h>
#include <linux/mount.h>
#include <linux/nsproxy.h>
#include <linux/pid.h>
#include <linux/pid_namespace.h>
#include <linux/sched.h>
#include <linux/slab.h>
#include <linux/string.h>
#include <linux/uaccess.h>
#include <linux/wait.h>

#include "agnocast_internal.h"

#ifndef CONFIG_POSIX_MQUEUE
#error "agnocast needs POSIX message queues (CONFIG_POSIX_MQUEUE)"
#endif

static DEFINE_MUTEX(agnocast_ns_list_lock);
static LIST_HEAD(agnocast_ns_list);
/* States on the list, shown in debugfs (agnocast/namespaces) for tests. */
static u32 agnocast_nr_ns;
static struct dentry *agnocast_debugfs;

/* The caller's namespace is alive (its nsproxy holds it), and so its mount. */
static struct vfsmount *agnocast_current_mq_mnt(void)
{
	return current->nsproxy->ipc_ns->mq_mnt;
}

int agnocast_ns_key_matches(const struct agnocast_ns *ns)
{
	return ns->mq_sb == agnocast_current_mq_mnt()->mnt_sb;
}

bool agnocast_ns_dead(const struct agnocast_ns *ns)
{
	return !READ_ONCE(ns->mq_sb->s_fs_info);
}

/*
 * Exit records.  A record is allocated when the thing it will describe is
 * created (a process registers, a callback subscriber is added), charged to
 * the creator's memory cgroup, and only moved to the namespace's list when
 * the process dies: teardown never allocates, so it cannot lose a record to
 * an allocation failure.  The list is bounded; past
 * AGNOCAST_EXIT_RECORDS_MAX the oldest records are discarded and counted,
 * and the reader is told how many before anything else.  The list is
 * protected by the namespace lock; readers are serialised by exit_read_lock.
 */

static void agnocast_exit_record_drop_oldest(struct agnocast_ns *ns)
{
	struct agnocast_exit_record_node *oldest;

	oldest = list_first_entry(&ns->exit_records, struct agnocast_exit_record_node, node);
	list_del(&oldest->node);
	agnocast_exit_record_free(oldest);
	WRITE_ONCE(ns->nr_exit_records, ns->nr_exit_records - 1);
	WRITE_ONCE(ns->exit_records_lost, ns->exit_records_lost + 1);
}

/* Fills @rec and appends it to the namespace's list, which takes it over. */
void agnocast_exit_record_queue(struct agnocast_ns *ns, struct agnocast_exit_record_node *rec,
				u32 kind, struct pid *pid, u32 subscriber_id, const char *topic)
{
	rec->kind = kind;
	rec->subscriber_id = subscriber_id;
	rec->pid = get_pid(pid);
	if (topic)
		strscpy(rec->topic, topic, sizeof(rec->topic));
	spin_lock(&ns->exit_lock);
	if (ns->nr_exit_records >= AGNOCAST_EXIT_RECORDS_MAX)
		agnocast_exit_record_drop_oldest(ns);
	rec->seq = ++ns->exit_records_seq;
	list_add_tail(&rec->node, &ns->exit_records);
	WRITE_ONCE(ns->nr_exit_records, ns->nr_exit_records + 1);
	spin_unlock(&ns->exit_lock);
}

void agnocast_exit_records_wake(struct agnocast_ns *ns)
{
	wake_up_interruptible(&ns->exit_wait);
}

bool agnocast_exit_records_waiting(const struct agnocast_ns *ns)
{
	return READ_ONCE(ns->nr_exit_records) || READ_ONCE(ns->exit_records_lost);
}

static void agnocast_exit_records_free(struct agnocast_ns *ns)
{
	struct agnocast_exit_record_node *rec, *tmp;

	list_for_each_entry_safe(rec, tmp, &ns->exit_records, node)
		agnocast_exit_record_free(rec);
	INIT_LIST_HEAD(&ns->exit_records);
	ns->nr_exit_records = 0;
	ns->exit_records_lost = 0;
}

/* Most records one read() returns: bounds the staging buffer. */
#define AGNOCAST_EXIT_READ_MAX 64

/*
 * Snapshots up to @max records (a LOST record first when some were
 * discarded) into @out; the namespace lock is held.  Returns the count and
 * the sequence number of the last record taken, for agnocast_exit_forget().
 */
static size_t agnocast_exit_snapshot(struct agnocast_ns *ns, struct agnocast_exit_record *out,
				     size_t max, struct pid_namespace *pid_ns, u64 *lost,
				     u64 *last_seq)
{
	struct agnocast_exit_record_node *rec;
	size_t n = 0;

	lockdep_assert_held(&ns->exit_lock);
	memset(out, 0, max * sizeof(*out));
	*lost = min_t(u64, ns->exit_records_lost, U32_MAX);
	if (*lost) {
		out[n].kind = AGNOCAST_EXIT_LOST;
		out[n].subscriber_id = *lost;
		n++;
	}
	*last_seq = 0;
	list_for_each_entry(rec, &ns->exit_records, node) {
		if (n == max)
			break;
		out[n].kind = rec->kind;
		out[n].pid = pid_nr_ns(rec->pid, pid_ns);
		out[n].subscriber_id = rec->subscriber_id;
		memcpy(out[n].topic, rec->topic, sizeof(out[n].topic));
		*last_seq = rec->seq;
		n++;
	}
	return n;
}

/* Forgets what a read delivered: @lost discards and records up to @last_seq. */
static void agnocast_exit_forget(struct agnocast_ns *ns, u64 lost, u64 last_seq)
{
	struct agnocast_exit_record_node *rec, *tmp;

	lockdep_assert_held(&ns->exit_lock);
	/* Discards since the snapshot may have taken delivered records: over-report. */
	WRITE_ONCE(ns->exit_records_lost, ns->exit_records_lost - min(lost, ns->exit_records_lost));
	list_for_each_entry_safe(rec, tmp, &ns->exit_records, node) {
		if (rec->seq > last_seq)
			break;
		list_del(&rec->node);
		agnocast_exit_record_free(rec);
		WRITE_ONCE(ns->nr_exit_records, ns->nr_exit_records - 1);
	}
}

/*
 * Copies whole records to @buf, oldest first.  The user copy happens with
 * only exit_read_lock held (readers are serialised; writers never wait for
 * it), and records are forgotten only once copied.
 */
ssize_t agnocast_read_exit_records(struct agnocast_ns *ns, char __user *buf, size_t count,
				   bool nonblock)
{
	struct pid_namespace *pid_ns = task_active_pid_ns(current);
	struct agnocast_exit_record *out;
	size_t max = min_t(size_t, count / sizeof(*out), AGNOCAST_EXIT_READ_MAX);
	u64 lost, last_seq;
	ssize_t ret;
	size_t n;

	if (!max)
		return -EINVAL;
	out = kvmalloc_array(max, sizeof(*out), GFP_KERNEL_ACCOUNT);
	if (!out)
		return -ENOMEM;
	ret = mutex_lock_killable(&ns->exit_read_lock);
	if (ret)
		goto out_free;

	for (;;) {
		spin_lock(&ns->exit_lock);
		if (agnocast_exit_records_waiting(ns))
			break;
		spin_unlock(&ns->exit_lock);
		ret = -EAGAIN;
		if (nonblock)
			goto out_unlock_read;
		ret = wait_event_interruptible(ns->exit_wait, agnocast_exit_records_waiting(ns));
		if (ret)
			goto out_unlock_read;
	}
	n = agnocast_exit_snapshot(ns, out, max, pid_ns, &lost, &last_seq);
	spin_unlock(&ns->exit_lock);

	ret = -EFAULT;
	if (copy_to_user(buf, out, n * sizeof(*out)))
		goto out_unlock_read;
	spin_lock(&ns->exit_lock);
	agnocast_exit_forget(ns, lost, last_seq);
	spin_unlock(&ns->exit_lock);
	ret = n * sizeof(*out);

out_unlock_read:
	mutex_unlock(&ns->exit_read_lock);
out_free:
	kvfree(out);
	return ret;
}

static struct agnocast_ns *agnocast_ns_alloc(void)
{
	struct agnocast_ns *ns;

	ns = kzalloc(sizeof(*ns), GFP_KERNEL_ACCOUNT);
	if (!ns)
		return NULL;
	ns->slot_map = bitmap_zalloc(agnocast_pool_count, GFP_KERNEL_ACCOUNT);
	if (!ns->slot_map)
		goto err_free_ns;
	ns->slots = kvcalloc(agnocast_pool_count, sizeof(*ns->slots), GFP_KERNEL_ACCOUNT);
	if (!ns->slots)
		goto err_free_map;

	ns->mq_mnt = mntget(agnocast_current_mq_mnt());
	ns->mq_sb = ns->mq_mnt->mnt_sb;
	mutex_init(&ns->exit_read_lock);
	init_rwsem(&ns->lock);
	spin_lock_init(&ns->exit_lock);
	INIT_LIST_HEAD(&ns->orphan_pools);
	INIT_LIST_HEAD(&ns->procs);
	hash_init(ns->topics);
	idr_init(&ns->topic_handles);
	hash_init(ns->id_spaces);
	INIT_LIST_HEAD(&ns->dormant_id_spaces);
	INIT_LIST_HEAD(&ns->exit_records);
	init_waitqueue_head(&ns->exit_wait);
	return ns;

err_free_map:
	bitmap_free(ns->slot_map);
err_free_ns:
	kfree(ns);
	return NULL;
}

/* Runs without agnocast_ns_list_lock: dropping the mount may free a superblock. */
static void agnocast_ns_free(struct agnocast_ns *ns)
{
	agnocast_exit_records_free(ns);
	agnocast_id_spaces_free(ns);
	agnocast_policy_free(ns->policy);
	idr_destroy(&ns->topic_handles);
	kvfree(ns->slots);
	bitmap_free(ns->slot_map);
	mutex_destroy(&ns->exit_read_lock);
	mntput(ns->mq_mnt);
	kfree(ns);
}

static void agnocast_ns_free_list(struct list_head *list)
{
	struct agnocast_ns *ns, *tmp;

	list_for_each_entry_safe(ns, tmp, list, list_node)
		agnocast_ns_free(ns);
}

/* Nobody can use the state again: free it. */
static bool agnocast_ns_finished(const struct agnocast_ns *ns)
{
	if (atomic_read(&ns->users) || ns->nr_procs)
		return false;
	if (agnocast_ns_dead(ns))
		return true;
	/* A live namespace keeps what nobody holds open: its policy, its records. */
	return !ns->nr_topics && !agnocast_exit_records_waiting(ns) && !ns->policy;
}

/* Moves finished states to @dead, to be freed after the list lock is dropped. */
static void agnocast_ns_collect(struct list_head *dead)
{
	struct agnocast_ns *ns, *tmp;

	lockdep_assert_held(&agnocast_ns_list_lock);
	list_for_each_entry_safe(ns, tmp, &agnocast_ns_list, list_node) {
		if (agnocast_ns_finished(ns)) {
			list_move(&ns->list_node, dead);
			WRITE_ONCE(agnocast_nr_ns, agnocast_nr_ns - 1);
		}
	}
}

/* Returns the caller's namespace state with a user reference, or NULL. */
struct agnocast_ns *agnocast_ns_get_current(void)
{
	struct agnocast_ns *ns;
	LIST_HEAD(dead);

	mutex_lock(&agnocast_ns_list_lock);
	agnocast_ns_collect(&dead);
	list_for_each_entry(ns, &agnocast_ns_list, list_node) {
		if (agnocast_ns_key_matches(ns))
			goto found;
	}
	ns = agnocast_ns_alloc();
	if (!ns)
		goto out_unlock;
	list_add(&ns->list_node, &agnocast_ns_list);
	WRITE_ONCE(agnocast_nr_ns, agnocast_nr_ns + 1);
found:
	atomic_inc(&ns->users);
out_unlock:
	mutex_unlock(&agnocast_ns_list_lock);
	agnocast_ns_free_list(&dead);
	return ns;
}

/* Takes another user reference; the caller must hold one or own a process. */
void agnocast_ns_get(struct agnocast_ns *ns)
{
	mutex_lock(&agnocast_ns_list_lock);
	atomic_inc(&ns->users);
	mutex_unlock(&agnocast_ns_list_lock);
}

void agnocast_ns_put(struct agnocast_ns *ns)
{
	bool finished;

	if (!atomic_dec_and_mutex_lock(&ns->users, &agnocast_ns_list_lock))
		return;
	finished = agnocast_ns_finished(ns);
	if (finished) {
		list_del(&ns->list_node);
		WRITE_ONCE(agnocast_nr_ns, agnocast_nr_ns - 1);
	}
	mutex_unlock(&agnocast_ns_list_lock);
	if (finished)
		agnocast_ns_free(ns);
}

void agnocast_ns_init(void)
{
	agnocast_debugfs = debugfs_create_dir("agnocast", NULL);
	debugfs_create_u32("namespaces", 0400, agnocast_debugfs, &agnocast_nr_ns);
}

/* Module exit: every file is closed and no process is registered. */
void agnocast_ns_exit(void)
{
	struct agnocast_ns *ns;
	LIST_HEAD(all);

	debugfs_remove_recursive(agnocast_debugfs);
	mutex_lock(&agnocast_ns_list_lock);
	list_for_each_entry(ns, &agnocast_ns_list, list_node)
		WARN_ON_ONCE(atomic_read(&ns->users) || ns->nr_procs);
	list_splice_init(&agnocast_ns_list, &all);
	agnocast_nr_ns = 0;
	mutex_unlock(&agnocast_ns_list_lock);
	agnocast_ns_free_list(&all);
}
