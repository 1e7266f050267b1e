// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: registered processes and their teardown.
 *
 * A process is keyed by its thread-group id (init-namespace number) in
 * agnocast_proc_table.  Its death is detected with a probe on the
 * sched_process_exit tracepoint rather than with the device file's release:
 * the probe fires for every way a process can die (kill -9 included) and for
 * any number of threads (we act on the last one, signal->live == 0), and
 * since it is keyed by tgid and not by file, a forked child that inherited
 * the descriptor neither keeps the parent's registration alive nor tears it
 * down.  The probe runs in atomic context, so it only marks the process dying
 * and queues its teardown on agnocast_wq; teardown runs under the namespace
 * lock in process context.
 *
 * exec is detected lazily: the registration records self_exec_id, and a call
 * from the same tgid with another exec id first tears the old registration
 * down as if the process had exited.
 *
 * Locking order (outermost first):
 *   agnocast_ns_list_lock -> agnocast_ns.lock -> agnocast_proc_table_lock
 * The table lock is a raw spinlock because the exit probe runs with
 * preemption disabled, where PREEMPT_RT's spinlock_t, a sleeping lock, must
 * not be taken.
 */
#include <linux/bitmap.h>
#include <linux/cred.h>
#include <linux/hashtable.h>
#include <linux/ipc_namespace.h>
#include <linux/module.h>
#include <linux/nsproxy.h>
#include <linux/pid.h>
#include <linux/pid_namespace.h>
#include <linux/sched.h>
#include <linux/sched/signal.h>
#include <linux/slab.h>
#include <linux/spinlock.h>
#include <linux/tracepoint.h>
#include <linux/uaccess.h>

#include "agnocast_internal.h"

static DEFINE_RAW_SPINLOCK(agnocast_proc_table_lock);
static DEFINE_HASHTABLE(agnocast_proc_table, 10);
static struct workqueue_struct *agnocast_wq;
static struct tracepoint *agnocast_exit_tp;

/* Finds the live registration of @tgid.  Dying ones are being torn down. */
static struct agnocast_proc *agnocast_proc_lookup(pid_t tgid)
{
	struct agnocast_proc *proc;

	lockdep_assert_held(&agnocast_proc_table_lock);
	hash_for_each_possible(agnocast_proc_table, proc, table_node, tgid) {
		if (proc->tgid == tgid && !proc->dying)
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
 * and holds the namespace lock.
 */
static void agnocast_proc_teardown(struct agnocast_proc *proc, bool record)
{
	struct agnocast_ns *ns = proc->ns;

	lockdep_assert_held(&ns->lock);
	raw_spin_lock(&agnocast_proc_table_lock);
	hash_del(&proc->table_node);
	raw_spin_unlock(&agnocast_proc_table_lock);

	if (record)
		agnocast_queue_exit_records(proc);
	agnocast_proc_drop_endpoints(proc);
	agnocast_proc_drop_reclaim(proc);
	agnocast_pool_drop_given(proc);
	proc->pool->owner = NULL;
	agnocast_pool_maybe_free(ns, proc->pool);

	list_del(&proc->ns_node);
	ns->nr_procs--;
	put_pid(proc->pid);
	agnocast_exit_record_free(proc->exit_record);
	bitmap_free(proc->given);
	kfree(proc);
	module_put(THIS_MODULE);
}

static void agnocast_teardown_work(struct work_struct *work)
{
	struct agnocast_proc *proc =
		container_of(work, struct agnocast_proc, teardown_work);
	struct agnocast_ns *ns = proc->ns;

	/* @proc keeps @ns from being freed until we hold a user reference. */
	agnocast_ns_get(ns);
	mutex_lock(&ns->lock);
	agnocast_proc_teardown(proc, true);
	mutex_unlock(&ns->lock);
	agnocast_ns_put(ns);
}

/*
 * sched_process_exit probe: atomic context, runs for every exiting thread
 * after it left signal->live; the last thread of a group sees 0.  Two threads
 * exiting together may both see 0, hence the dying flag.
 */
static void agnocast_on_process_exit(void *data, struct task_struct *p)
{
	struct agnocast_proc *proc;

	if (atomic_read(&p->signal->live))
		return;
	raw_spin_lock(&agnocast_proc_table_lock);
	proc = agnocast_proc_lookup(p->tgid);
	if (proc) {
		proc->dying = true;
		queue_work(agnocast_wq, &proc->teardown_work);
	}
	raw_spin_unlock(&agnocast_proc_table_lock);
}

static void agnocast_find_exit_tp(struct tracepoint *tp, void *priv)
{
	if (!strcmp(tp->name, "sched_process_exit"))
		*(struct tracepoint **)priv = tp;
}

int agnocast_process_init(void)
{
	int ret;

	for_each_kernel_tracepoint(agnocast_find_exit_tp, &agnocast_exit_tp);
	if (!agnocast_exit_tp) {
		pr_err("agnocast: tracepoint sched_process_exit not found\n");
		return -ENOENT;
	}
	agnocast_wq = alloc_workqueue("agnocast", WQ_UNBOUND, 0);
	if (!agnocast_wq)
		return -ENOMEM;
	ret = tracepoint_probe_register(agnocast_exit_tp, agnocast_on_process_exit, NULL);
	if (ret) {
		pr_err("agnocast: cannot probe sched_process_exit: %d\n", ret);
		destroy_workqueue(agnocast_wq);
		return ret;
	}
	return 0;
}

void agnocast_process_exit(void)
{
	tracepoint_probe_unregister(agnocast_exit_tp, agnocast_on_process_exit, NULL);
	tracepoint_synchronize_unregister();
	/* Waits for teardowns still running (they hold the module until done). */
	destroy_workqueue(agnocast_wq);
}

/* Takes the namespace lock and finds the caller's registration. */
int agnocast_enter(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns, bool registered)
{
	struct agnocast_proc *proc, *stale = NULL;
	bool other_ns = false;

	ctx->proc = NULL;
	/*
	 * The open file holds a reference on the state of the namespace it was
	 * opened in; while the caller is still in that namespace, use it and
	 * skip the global namespace list.
	 */
	ctx->ns_from_file = file_ns && agnocast_ns_key_matches(file_ns);
	ctx->ns = ctx->ns_from_file ? file_ns : agnocast_ns_get_current();
	if (!ctx->ns)
		return -ENOMEM;
	mutex_lock(&ctx->ns->lock);

	raw_spin_lock(&agnocast_proc_table_lock);
	proc = agnocast_proc_lookup(current->tgid);
	if (proc && proc->ns != ctx->ns) {
		other_ns = true;
	} else if (proc && proc->exec_id != current->self_exec_id) {
		proc->dying = true;
		stale = proc;
	} else {
		ctx->proc = proc;
	}
	raw_spin_unlock(&agnocast_proc_table_lock);

	if (stale)
		agnocast_proc_teardown(stale, true);
	if (other_ns || (registered && !ctx->proc)) {
		agnocast_leave(ctx);
		return other_ns ? -EXDEV : -ESRCH;
	}
	return 0;
}

void agnocast_leave(struct agnocast_ctx *ctx)
{
	mutex_unlock(&ctx->ns->lock);
	if (!ctx->ns_from_file)
		agnocast_ns_put(ctx->ns);
}

static struct agnocast_proc *agnocast_proc_create(struct agnocast_ns *ns, int *err)
{
	struct agnocast_proc *proc;

	lockdep_assert_held(&ns->lock);
	*err = -ENOMEM;
	proc = kzalloc(sizeof(*proc), GFP_KERNEL_ACCOUNT);
	if (!proc)
		return NULL;
	proc->given = bitmap_zalloc(agnocast_pool_count, GFP_KERNEL_ACCOUNT);
	if (!proc->given)
		goto err_free_proc;
	proc->exit_record = agnocast_exit_record_alloc();
	if (!proc->exit_record)
		goto err_free_given;
	proc->pool = agnocast_pool_reserve(ns, proc);
	if (IS_ERR(proc->pool)) {
		*err = PTR_ERR(proc->pool);
		goto err_free_given;
	}
	if (!try_module_get(THIS_MODULE)) {
		*err = -ENODEV;
		goto err_free_pool;
	}
	proc->tgid = current->tgid;
	proc->exec_id = current->self_exec_id;
	proc->uid = current_euid();
	proc->pid = get_task_pid(current, PIDTYPE_TGID);
	proc->ns = ns;
	INIT_WORK(&proc->teardown_work, agnocast_teardown_work);
	INIT_LIST_HEAD(&proc->publishers);
	INIT_LIST_HEAD(&proc->subscribers);
	INIT_LIST_HEAD(&proc->reclaim);
	INIT_LIST_HEAD(&proc->spare_entries);
	INIT_LIST_HEAD(&proc->spare_held);
	list_add_tail(&proc->ns_node, &ns->procs);
	ns->nr_procs++;

	raw_spin_lock(&agnocast_proc_table_lock);
	hash_add(agnocast_proc_table, &proc->table_node, proc->tgid);
	raw_spin_unlock(&agnocast_proc_table_lock);
	*err = 0;
	return proc;

err_free_pool:
	proc->pool->owner = NULL;
	agnocast_pool_maybe_free(ns, proc->pool);
err_free_given:
	agnocast_exit_record_free(proc->exit_record);
	bitmap_free(proc->given);
err_free_proc:
	kfree(proc);
	return NULL;
}

int agnocast_register_process(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_register_process arg;
	struct agnocast_ctx ctx;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.pool_fd < -1)
		return -EBADF;

	ret = agnocast_enter(&ctx, file_ns, false);
	if (ret)
		return ret;
	if (arg.pool_fd == -1) {
		if (!ctx.proc)
			ctx.proc = agnocast_proc_create(ctx.ns, &ret);
	} else if (!ctx.proc) {
		ret = -ESRCH;
	} else {
		ret = agnocast_pool_attach(ctx.proc->pool, arg.pool_fd);
	}
	if (ctx.proc && !ret) {
		arg.pid = task_tgid_vnr(current);
		arg.pool_addr = ctx.proc->pool->addr;
		arg.pool_size = ctx.proc->pool->size;
	}
	agnocast_leave(&ctx);
	if (ret)
		return ret;
	if (copy_to_user(uarg, &arg, sizeof(arg)))
		return -EFAULT;
	return 0;
}

int agnocast_unregister_process(struct agnocast_ns *file_ns)
{
	struct agnocast_ctx ctx;
	int ret;

	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	raw_spin_lock(&agnocast_proc_table_lock);
	ctx.proc->dying = true;
	raw_spin_unlock(&agnocast_proc_table_lock);
	agnocast_proc_teardown(ctx.proc, false);
	agnocast_leave(&ctx);
	return 0;
}
