// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: exit records, the namespace's list of what dead processes left
 * behind (their notification queues), read by the daemon through read().
 *
 * A record is allocated when the thing it will describe is created (a
 * process registers, a callback subscriber is added), charged to the
 * creator's memory cgroup, and only moved to the namespace's list when the
 * process dies: teardown never allocates, so it cannot lose a record to an
 * allocation failure.  The list is bounded; past AGNOCAST_EXIT_RECORDS_MAX
 * the oldest records are discarded and counted, and the reader is told how
 * many before anything else.
 *
 * All state here is protected by the namespace lock (agnocast_ns.lock).
 */
#include <linux/capability.h>
#include <linux/list.h>
#include <linux/mm.h>
#include <linux/nsproxy.h>
#include <linux/ipc_namespace.h>
#include <linux/pid.h>
#include <linux/pid_namespace.h>
#include <linux/sched.h>
#include <linux/slab.h>
#include <linux/string.h>
#include <linux/uaccess.h>
#include <linux/wait.h>

#include "agnocast_internal.h"

struct agnocast_exit_record_node {
	struct list_head node;
	u32 kind;
	u32 subscriber_id;
	u64 seq;			/* order of queueing, from 1 */
	struct pid *pid;
	char topic[AGNOCAST_TOPIC_NAME_MAX];
};

struct agnocast_exit_record_node *agnocast_exit_record_alloc(void)
{
	return kzalloc(sizeof(struct agnocast_exit_record_node), GFP_KERNEL_ACCOUNT);
}

void agnocast_exit_record_free(struct agnocast_exit_record_node *rec)
{
	if (!rec)
		return;
	put_pid(rec->pid);
	kfree(rec);
}

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
	lockdep_assert_held(&ns->lock);
	rec->kind = kind;
	rec->subscriber_id = subscriber_id;
	rec->pid = get_pid(pid);
	if (topic)
		strscpy(rec->topic, topic, sizeof(rec->topic));
	if (ns->nr_exit_records >= AGNOCAST_EXIT_RECORDS_MAX)
		agnocast_exit_record_drop_oldest(ns);
	rec->seq = ++ns->exit_records_seq;
	list_add_tail(&rec->node, &ns->exit_records);
	WRITE_ONCE(ns->nr_exit_records, ns->nr_exit_records + 1);
}

void agnocast_exit_records_wake(struct agnocast_ns *ns)
{
	wake_up_interruptible(&ns->exit_wait);
}

bool agnocast_exit_records_waiting(const struct agnocast_ns *ns)
{
	return READ_ONCE(ns->nr_exit_records) || READ_ONCE(ns->exit_records_lost);
}

void agnocast_exit_records_free(struct agnocast_ns *ns)
{
	struct agnocast_exit_record_node *rec, *tmp;

	list_for_each_entry_safe(rec, tmp, &ns->exit_records, node)
		agnocast_exit_record_free(rec);
	INIT_LIST_HEAD(&ns->exit_records);
	ns->nr_exit_records = 0;
	ns->exit_records_lost = 0;
}

static bool agnocast_may_read_exit_records(struct agnocast_ns *ns)
{
	if (!agnocast_ns_key_matches(ns))
		return false;
	return ns_capable(current->nsproxy->ipc_ns->user_ns, CAP_SYS_ADMIN);
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

	lockdep_assert_held(&ns->lock);
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

	lockdep_assert_held(&ns->lock);
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

	if (!agnocast_may_read_exit_records(ns))
		return -EPERM;
	if (!max)
		return -EINVAL;
	out = kvmalloc_array(max, sizeof(*out), GFP_KERNEL_ACCOUNT);
	if (!out)
		return -ENOMEM;
	ret = mutex_lock_killable(&ns->exit_read_lock);
	if (ret)
		goto out_free;

	for (;;) {
		mutex_lock(&ns->lock);
		if (agnocast_exit_records_waiting(ns))
			break;
		mutex_unlock(&ns->lock);
		ret = -EAGAIN;
		if (nonblock)
			goto out_unlock_read;
		ret = wait_event_interruptible(ns->exit_wait, agnocast_exit_records_waiting(ns));
		if (ret)
			goto out_unlock_read;
	}
	n = agnocast_exit_snapshot(ns, out, max, pid_ns, &lost, &last_seq);
	mutex_unlock(&ns->lock);

	ret = -EFAULT;
	if (copy_to_user(buf, out, n * sizeof(*out)))
		goto out_unlock_read;
	mutex_lock(&ns->lock);
	agnocast_exit_forget(ns, lost, last_seq);
	mutex_unlock(&ns->lock);
	ret = n * sizeof(*out);

out_unlock_read:
	mutex_unlock(&ns->exit_read_lock);
out_free:
	kvfree(out);
	return ret;
}
