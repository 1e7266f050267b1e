// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: registered processes and their teardown.
 *
 * A process is keyed by its thread-group id (init-namespace number) in
 * agnocast_proc_table.  Its death is detected with a probe on the
 * sched_process_exit tracepoint rather than with the device file's release:
 * the probe fires for every way a process can die (kill -9 included) and for
 * any number of threads (we act on the last one), and since it is keyed by
 * tgid and not by file, a forked child that inherited the descriptor neither
 * keeps the parent's registration alive nor tears it down.  exec is detected
 * when it happens, by a probe on sched_process_exec, and handled like an
 * exit: the new program starts unregistered.
 *
 * The probes only mark the process dying and queue its teardown on
 * agnocast_wq; teardown runs in process context with the namespace lock held
 * for write.  They take nothing but the table's raw spinlock (a
 * PREEMPT_RT spinlock_t would sleep) and queue_work(), which uses raw locks.
 *
 * Calls find the caller's record by tgid under RCU, without a lock: records
 * leave the table under the raw spinlock and are freed after a grace period.
 * A call that finds its process's record dying waits for the teardown
 * (the old program's, after exec), so it sees the process unregistered.
 */
#include <linux/bitmap.h>
#include <linux/cred.h>
#include <linux/hashtable.h>
#include <linux/module.h>
#include <linux/pid.h>
#include <linux/rculist.h>
#include <linux/sched.h>
#include <linux/sched/signal.h>
#include <linux/slab.h>
#include <linux/spinlock.h>
#include <linux/tracepoint.h>

#include "agnocast_internal.h"
#include "agnocast_trace.h"

static DEFINE_RAW_SPINLOCK(agnocast_proc_table_lock);
static DEFINE_HASHTABLE(agnocast_proc_table, 10);
static struct workqueue_struct *agnocast_wq;

/*
 * Finds the live registration of @tgid, under RCU or the table lock.  Dying
 * ones are being torn down.
 */
static struct agnocast_proc *agnocast_proc_lookup(pid_t tgid)
{
	struct agnocast_proc *proc;

	hash_for_each_possible_rcu(agnocast_proc_table, proc, table_node, tgid,
				   lockdep_is_held(&agnocast_proc_table_lock)) {
		if (proc->tgid == tgid && !READ_ONCE(proc->dying))
			return proc;
	}
	return NULL;
}

static void agnocast_queue_exit_records(struct agnocast_proc *proc)
{
	struct agnocast_ns *ns = proc->ns;
	struct agnocast_subscriber *sub;
	struct agnocast_endpoint *ep;

	list_for_each_entry(ep, &proc->subscribers, proc_node) {
		sub = agnocast_to_subscriber(ep);
		if (!sub->exit_record)
			continue;
		agnocast_exit_record_queue(ns, sub->exit_record, AGNOCAST_EXIT_QUEUE, proc->pid,
					   ep->id, ep->topic->name);
		sub->exit_record = NULL;
	}
	agnocast_exit_record_queue(ns, proc->exit_record, AGNOCAST_EXIT_PROCESS, proc->pid, 0,
				   NULL);
	proc->exit_record = NULL;
	agnocast_exit_records_wake(ns);
}

/*
 * Drops everything @proc holds and frees it.  The caller has set proc->dying
 * and holds the namespace lock for write.
 */
static void agnocast_proc_teardown(struct agnocast_proc *proc, bool record)
{
	struct agnocast_ns *ns = proc->ns;

	lockdep_assert_held_write(&ns->lock);
	raw_spin_lock(&agnocast_proc_table_lock);
	hash_del_rcu(&proc->table_node);
	raw_spin_unlock(&agnocast_proc_table_lock);

	trace_process_exit(proc, record);
	if (record)
		agnocast_queue_exit_records(proc);
	agnocast_wake_publisher_gone(proc);
	agnocast_proc_drop_endpoints(proc);
	agnocast_wake_put_eventfd(proc);
	agnocast_proc_drop_reclaim(proc);
	agnocast_pool_drop_given(proc);
	agnocast_pool_orphan(ns, proc->pool);
	agnocast_pools_collect(ns);

	list_del(&proc->ns_node);
	ns->nr_procs--;
	put_pid(proc->pid);
	agnocast_exit_record_free(proc->exit_record);
	bitmap_free(proc->given);
	/* Lookups under RCU may still see it. */
	kfree_rcu(proc, rcu);
	module_put(THIS_MODULE);
}

static void agnocast_teardown_work(struct work_struct *work)
{
	struct agnocast_proc *proc =
		container_of(work, struct agnocast_proc, teardown_work);
	struct agnocast_ns *ns = proc->ns;

	/* @proc keeps @ns from being freed until we hold a user reference. */
	agnocast_ns_get(ns);
	down_write(&ns->lock);
	agnocast_proc_teardown(proc, true);
	up_write(&ns->lock);
	agnocast_ns_put(ns);
}

/* Marks @tgid's registration dying and queues its teardown. */
static void agnocast_proc_end(pid_t tgid)
{
	struct agnocast_proc *proc;

	raw_spin_lock(&agnocast_proc_table_lock);
	proc = agnocast_proc_lookup(tgid);
	if (proc) {
		WRITE_ONCE(proc->dying, true);
		queue_work(agnocast_wq, &proc->teardown_work);
	}
	raw_spin_unlock(&agnocast_proc_table_lock);
}

/*
 * sched_process_exit probe: runs for every exiting thread after it left
 * signal->live; the last thread of a group sees 0.  Two threads exiting
 * together may both see 0, hence the dying flag.  Newer kernels pass
 * group_dead, which says the same (AGNOCAST_EXIT_TP_GROUP_DEAD, set by Kbuild
 * from the tracepoint's prototype in the headers built against).
 */
#ifdef AGNOCAST_EXIT_TP_GROUP_DEAD
static void agnocast_on_process_exit(void *data, struct task_struct *p, bool group_dead)
{
	if (group_dead)
		agnocast_proc_end(p->tgid);
}
#else
static void agnocast_on_process_exit(void *data, struct task_struct *p)
{
	if (!atomic_read(&p->signal->live))
		agnocast_proc_end(p->tgid);
}
#endif

/*
 * sched_process_exec probe: the old program is gone; everything it
 * registered goes as at exit.  A multi-threaded exec has made the caller
 * the group leader by now, with the same tgid.
 */
static void agnocast_on_process_exec(void *data, struct task_struct *p, pid_t old_pid,
				     struct linux_binprm *bprm)
{
	agnocast_proc_end(p->tgid);
}

struct agnocast_tracepoints {
	struct tracepoint *exit;
	struct tracepoint *exec;
};

static struct agnocast_tracepoints agnocast_tps;

static void agnocast_find_tps(struct tracepoint *tp, void *priv)
{
	struct agnocast_tracepoints *tps = priv;

	if (!strcmp(tp->name, "sched_process_exit"))
		tps->exit = tp;
	else if (!strcmp(tp->name, "sched_process_exec"))
		tps->exec = tp;
}

int agnocast_process_init(void)
{
	int ret;

	for_each_kernel_tracepoint(agnocast_find_tps, &agnocast_tps);
	if (!agnocast_tps.exit || !agnocast_tps.exec) {
		pr_err("agnocast: tracepoint sched_process_exit or sched_process_exec not found\n");
		return -ENOENT;
	}
	agnocast_wq = alloc_workqueue("agnocast", WQ_UNBOUND, 0);
	if (!agnocast_wq)
		return -ENOMEM;
	ret = tracepoint_probe_register(agnocast_tps.exit, agnocast_on_process_exit, NULL);
	if (ret) {
		pr_err("agnocast: cannot probe sched_process_exit: %d\n", ret);
		goto err_destroy_wq;
	}
	ret = tracepoint_probe_register(agnocast_tps.exec, agnocast_on_process_exec, NULL);
	if (ret) {
		pr_err("agnocast: cannot probe sched_process_exec: %d\n", ret);
		goto err_unregister_exit;
	}
	return 0;

err_unregister_exit:
	tracepoint_probe_unregister(agnocast_tps.exit, agnocast_on_process_exit, NULL);
	tracepoint_synchronize_unregister();
err_destroy_wq:
	destroy_workqueue(agnocast_wq);
	return ret;
}

void agnocast_process_exit(void)
{
	tracepoint_probe_unregister(agnocast_tps.exec, agnocast_on_process_exec, NULL);
	tracepoint_probe_unregister(agnocast_tps.exit, agnocast_on_process_exit, NULL);
	tracepoint_synchronize_unregister();
	/* Waits for teardowns still running (they hold the module until done). */
	destroy_workqueue(agnocast_wq);
	/* Records freed with kfree_rcu() must be gone before the module is. */
	rcu_barrier();
}

/* Waits until the registrations that are dying are torn down. */
void agnocast_proc_settle(void)
{
	flush_workqueue(agnocast_wq);
}

/*
 * The caller's registration in @ns, NULL if none (@ns->lock held, under which
 * a record of the namespace stays); -EXDEV if it is registered in another;
 * -EAGAIN while a registration of its process is dying (the old program's,
 * after exec): drop the lock, agnocast_proc_settle(), and look again.
 */
int agnocast_proc_find_current(struct agnocast_ns *ns, struct agnocast_proc **out)
{
	struct agnocast_proc *proc, *found = NULL;
	pid_t tgid = current->tgid;
	int ret = 0;

	lockdep_assert_held(&ns->lock);
	rcu_read_lock();
	hash_for_each_possible_rcu(agnocast_proc_table, proc, table_node, tgid) {
		if (proc->tgid != tgid)
			continue;
		if (READ_ONCE(proc->dying)) {
			ret = -EAGAIN;
			found = NULL;
			break;
		}
		found = proc;
	}
	if (found && found->ns != ns) {
		found = NULL;
		ret = -EXDEV;
	}
	rcu_read_unlock();
	*out = found;
	return ret;
}

/* Registers the caller in @ns (lock held for write) with a reserved pool slot. */
struct agnocast_proc *agnocast_proc_create(struct agnocast_ns *ns)
{
	struct agnocast_proc *proc;
	int err = -ENOMEM;

	lockdep_assert_held_write(&ns->lock);
	proc = kzalloc(sizeof(*proc), GFP_KERNEL_ACCOUNT);
	if (!proc)
		return ERR_PTR(-ENOMEM);
	proc->given = bitmap_zalloc(agnocast_pool_count, GFP_KERNEL_ACCOUNT);
	if (!proc->given)
		goto err_free_proc;
	proc->exit_record = agnocast_exit_record_alloc();
	if (!proc->exit_record)
		goto err_free_given;
	proc->pool = agnocast_pool_reserve(ns, proc);
	if (IS_ERR(proc->pool)) {
		err = PTR_ERR(proc->pool);
		goto err_free_given;
	}
	if (!try_module_get(THIS_MODULE)) {
		err = -ENODEV;
		goto err_free_pool;
	}
	proc->tgid = current->tgid;
	proc->uid = current_euid();
	proc->pid = get_task_pid(current, PIDTYPE_TGID);
	proc->ns = ns;
	INIT_WORK(&proc->teardown_work, agnocast_teardown_work);
	INIT_LIST_HEAD(&proc->publishers);
	INIT_LIST_HEAD(&proc->subscribers);
	spin_lock_init(&proc->reclaim_lock);
	INIT_LIST_HEAD(&proc->reclaim);
	list_add_tail(&proc->ns_node, &ns->procs);
	ns->nr_procs++;

	raw_spin_lock(&agnocast_proc_table_lock);
	hash_add_rcu(agnocast_proc_table, &proc->table_node, proc->tgid);
	raw_spin_unlock(&agnocast_proc_table_lock);
	return proc;

err_free_pool:
	agnocast_pool_orphan(ns, proc->pool);
	agnocast_pools_collect(ns);
err_free_given:
	agnocast_exit_record_free(proc->exit_record);
	bitmap_free(proc->given);
err_free_proc:
	kfree(proc);
	return ERR_PTR(err);
}

/* UNREGISTER_PROCESS: @proc goes as at exit, without exit records. */
void agnocast_proc_unregister(struct agnocast_proc *proc)
{
	lockdep_assert_held_write(&proc->ns->lock);
	raw_spin_lock(&agnocast_proc_table_lock);
	WRITE_ONCE(proc->dying, true);
	raw_spin_unlock(&agnocast_proc_table_lock);
	agnocast_proc_teardown(proc, false);
}
