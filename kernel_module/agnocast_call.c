// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: the call context every ioctl handler works in.
 *
 * A handler copies its argument in, enters (takes the namespace lock and
 * finds the caller's registration), calls down into the state files, leaves,
 * and copies its answer out.  Which lock a call takes is said by the variant
 * it enters with:
 *
 *   agnocast_enter_read()      registered caller, namespace lock for read:
 *                              the data path (PUBLISH, RECLAIM, RECEIVE,
 *                              TAKE, RELEASE, SHED)
 *   agnocast_enter_write()     registered caller, for write: what changes
 *                              the namespace's structure (endpoints,
 *                              unregistering)
 *   agnocast_enter_ns_read()   any caller, for read: introspection,
 *                              GET_POLICY
 *   agnocast_enter_ns_write()  any caller, for write: REGISTER_PROCESS,
 *                              SET_POLICY
 *
 * Output buffers are checked writable before anything commits, so that a
 * call fails with -EFAULT only while it has done nothing.  They are written
 * after the namespace lock is dropped; should another thread unmap them in
 * between, the call still reports success (it happened) and what it could
 * not write is lost, except reclaimable addresses, which stay pending.
 */
#include <linux/sched.h>
#include <linux/uaccess.h>

#include "agnocast_internal.h"

/*
 * Takes the namespace lock (for write if @write), killably, and finds the
 * caller's registration (required if @registered).
 */
static int agnocast_enter(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns,
			  bool registered, bool write)
{
	int ret;

	ctx->proc = NULL;
	ctx->write = write;
	/*
	 * The open file holds a reference on the state of the namespace it was
	 * opened in; while the caller is still in that namespace, use it and
	 * skip the global namespace list.
	 */
	ctx->ns_from_file = file_ns && agnocast_ns_key_matches(file_ns);
	ctx->ns = ctx->ns_from_file ? file_ns : agnocast_ns_get_current();
	if (!ctx->ns)
		return -ENOMEM;
relock:
	ret = write ? down_write_killable(&ctx->ns->lock) : down_read_killable(&ctx->ns->lock);
	if (ret) {
		if (!ctx->ns_from_file)
			agnocast_ns_put(ctx->ns);
		return ret;
	}
	ret = agnocast_proc_find_current(ctx->ns, &ctx->proc);
	if (ret == -EAGAIN) {
		/* After exec, the old program's registration goes before the new one calls. */
		if (write)
			up_write(&ctx->ns->lock);
		else
			up_read(&ctx->ns->lock);
		agnocast_proc_settle();
		goto relock;
	}
	if (!ret && registered && !ctx->proc)
		ret = -ESRCH;
	if (ret)
		agnocast_leave(ctx);
	return ret;
}

int agnocast_enter_read(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns)
{
	return agnocast_enter(ctx, file_ns, true, false);
}

int agnocast_enter_write(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns)
{
	return agnocast_enter(ctx, file_ns, true, true);
}

int agnocast_enter_ns_read(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns)
{
	return agnocast_enter(ctx, file_ns, false, false);
}

int agnocast_enter_ns_write(struct agnocast_ctx *ctx, struct agnocast_ns *file_ns)
{
	return agnocast_enter(ctx, file_ns, false, true);
}

/* Drops the namespace lock; frees pools the call left ownerless and empty. */
void agnocast_leave(struct agnocast_ctx *ctx)
{
	struct agnocast_ns *ns = ctx->ns;

	if (ctx->write) {
		if (ns->collect_pools)
			agnocast_pools_collect(ns);
		up_write(&ns->lock);
	} else {
		up_read(&ns->lock);
		if (READ_ONCE(ns->collect_pools)) {
			down_write(&ns->lock);
			agnocast_pools_collect(ns);
			up_write(&ns->lock);
		}
	}
	if (!ctx->ns_from_file)
		agnocast_ns_put(ns);
}

/*
 * An unwritable output is -EFAULT, but an unregistered caller learns that
 * first, as it would if the buffers were fine.
 */
int agnocast_unwritable(struct agnocast_ns *file_ns)
{
	struct agnocast_ctx ctx;
	int ret;

	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		return ret;
	agnocast_leave(&ctx);
	return -EFAULT;
}
