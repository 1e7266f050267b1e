// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: per-IPC-namespace state.
 *
 * Topics, ids, pool slots and exit records belong to the IPC namespace of the
 * calling process, like POSIX message queues.  put_ipc_ns() is not exported,
 * so no reference on the namespace is taken: the state is keyed by the
 * namespace's address plus its inode number and freed as soon as it is idle
 * (no users, no processes, no topics, no exit records).
 *
 * Locking order (outermost first):
 *   agnocast_ns_list_lock -> agnocast_ns.lock -> agnocast_proc_table_lock
 * agnocast_ns.users is incremented only under agnocast_ns_list_lock (or while
 * already nonzero by the holder of a user) and drops to 0 only under it, so a
 * state seen with users == 0 under agnocast_ns_list_lock has no lock holder
 * and may be read and freed without agnocast_ns.lock.  An ioctl on a file
 * opened in the caller's namespace borrows the file's user reference (held
 * until release, which cannot run during the ioctl) instead of taking one.
 */
#include <linux/bitmap.h>
#include <linux/ipc_namespace.h>
#include <linux/nsproxy.h>
#include <linux/sched.h>
#include <linux/slab.h>

#include "agnocast_internal.h"

static DEFINE_MUTEX(agnocast_ns_list_lock);
static LIST_HEAD(agnocast_ns_list);

static struct ipc_namespace *agnocast_current_ipc_ns(void)
{
	return current->nsproxy->ipc_ns;
}

int agnocast_ns_key_matches(const struct agnocast_ns *ns)
{
	struct ipc_namespace *ipc_ns = agnocast_current_ipc_ns();

	return ns->ipc_ns == ipc_ns && ns->ipc_inum == ipc_ns->ns.inum;
}

static struct agnocast_ns *agnocast_ns_alloc(void)
{
	struct ipc_namespace *ipc_ns = agnocast_current_ipc_ns();
	struct agnocast_ns *ns;

	ns = kzalloc(sizeof(*ns), GFP_KERNEL);
	if (!ns)
		return NULL;
	ns->slot_map = bitmap_zalloc(agnocast_pool_count, GFP_KERNEL);
	if (!ns->slot_map)
		goto err_free_ns;
	ns->slots = kvcalloc(agnocast_pool_count, sizeof(*ns->slots), GFP_KERNEL);
	if (!ns->slots)
		goto err_free_map;

	ns->ipc_ns = ipc_ns;
	ns->ipc_inum = ipc_ns->ns.inum;
	mutex_init(&ns->lock);
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

static void agnocast_ns_free(struct agnocast_ns *ns)
{
	agnocast_exit_records_free(ns);
	agnocast_id_spaces_free(ns);
	idr_destroy(&ns->topic_handles);
	kvfree(ns->slots);
	bitmap_free(ns->slot_map);
	mutex_destroy(&ns->lock);
	kfree(ns);
}

static bool agnocast_ns_idle(const struct agnocast_ns *ns)
{
	return !atomic_read(&ns->users) && !ns->nr_procs && !ns->nr_topics &&
	       !ns->nr_exit_records;
}

/* Returns the caller's namespace state with a user reference, or NULL. */
struct agnocast_ns *agnocast_ns_get_current(void)
{
	struct agnocast_ns *ns;

	mutex_lock(&agnocast_ns_list_lock);
	list_for_each_entry(ns, &agnocast_ns_list, list_node) {
		if (agnocast_ns_key_matches(ns))
			goto found;
	}
	ns = agnocast_ns_alloc();
	if (!ns)
		goto out_unlock;
	list_add(&ns->list_node, &agnocast_ns_list);
found:
	atomic_inc(&ns->users);
out_unlock:
	mutex_unlock(&agnocast_ns_list_lock);
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
	if (!atomic_dec_and_mutex_lock(&ns->users, &agnocast_ns_list_lock))
		return;
	if (agnocast_ns_idle(ns)) {
		list_del(&ns->list_node);
		agnocast_ns_free(ns);
	}
	mutex_unlock(&agnocast_ns_list_lock);
}

/* Module exit: every file is closed and no process is registered. */
void agnocast_ns_exit(void)
{
	struct agnocast_ns *ns, *tmp;

	mutex_lock(&agnocast_ns_list_lock);
	list_for_each_entry_safe(ns, tmp, &agnocast_ns_list, list_node) {
		WARN_ON_ONCE(atomic_read(&ns->users) || ns->nr_procs);
		list_del(&ns->list_node);
		agnocast_ns_free(ns);
	}
	mutex_unlock(&agnocast_ns_list_lock);
}
