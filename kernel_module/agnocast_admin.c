// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: the administrative commands: REGISTER_PROCESS,
 * UNREGISTER_PROCESS, SET_POLICY, GET_POLICY.
 *
 * Like every handler, each copies its argument in, enters the call context
 * (agnocast_call.c), calls down into processes (agnocast_process.c), pools
 * and the policy (agnocast_policy.c), leaves, and copies its answer out.
 */
#include <linux/capability.h>
#include <linux/eventfd.h>
#include <linux/ipc_namespace.h>
#include <linux/nsproxy.h>
#include <linux/overflow.h>
#include <linux/sched.h>
#include <linux/slab.h>
#include <linux/uaccess.h>

#include "agnocast_internal.h"

int agnocast_register_process(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_register_process arg;
	struct eventfd_ctx *wake = NULL;
	struct agnocast_ctx ctx;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.flags & ~AGNOCAST_REGISTER_WAKE_EVENTFD)
		return -EINVAL;
	if (!(arg.flags & AGNOCAST_REGISTER_WAKE_EVENTFD) && arg.wake_fd)
		return -EINVAL;
	if (arg.pool_fd < -1)
		return -EBADF;
	if (arg.flags & AGNOCAST_REGISTER_WAKE_EVENTFD) {
		wake = eventfd_ctx_fdget(arg.wake_fd);
		if (IS_ERR(wake))
			return PTR_ERR(wake);
	}

	ret = agnocast_enter_ns_write(&ctx, file_ns);
	if (ret)
		goto out_put;
	/*
	 * Set once: the watchdog signals it under no lock, so replacing it
	 * could free it under the timer.
	 */
	if (wake && ctx.proc && ctx.proc->wake_eventfd) {
		ret = -EEXIST;
	} else if (arg.pool_fd == -1) {
		if (!ctx.proc) {
			ctx.proc = agnocast_proc_create(ctx.ns);
			if (IS_ERR(ctx.proc)) {
				ret = PTR_ERR(ctx.proc);
				ctx.proc = NULL;
			}
		}
	} else if (!ctx.proc) {
		ret = -ESRCH;
	} else {
		ret = agnocast_pool_attach(ctx.proc->pool, arg.pool_fd);
	}
	if (ctx.proc && !ret && wake) {
		agnocast_wake_set_eventfd(ctx.proc, wake);
		wake = NULL;
	}
	if (ctx.proc && !ret) {
		arg.pid = task_tgid_vnr(current);
		arg.pool_addr = ctx.proc->pool->addr;
		arg.pool_size = ctx.proc->pool->size;
	}
	agnocast_leave(&ctx);
	if (!ret && copy_to_user(uarg, &arg, sizeof(arg)))
		ret = -EFAULT;
out_put:
	if (wake)
		eventfd_ctx_put(wake);
	return ret;
}

int agnocast_unregister_process(struct agnocast_ns *file_ns)
{
	struct agnocast_ctx ctx;
	int ret;

	ret = agnocast_enter_write(&ctx, file_ns);
	if (ret)
		return ret;
	agnocast_proc_unregister(ctx.proc);
	agnocast_leave(&ctx);
	return 0;
}

/* Copies a policy's arrays in and builds it; no lock held. */
static struct agnocast_policy_state *agnocast_policy_in(const struct agnocast_policy *arg)
{
	struct agnocast_principal *principals = NULL;
	struct agnocast_policy_rule *rules = NULL;
	struct agnocast_policy_state *policy;

	if (!agnocast_policy_arg_valid(arg))
		return ERR_PTR(-EINVAL);
	policy = ERR_PTR(-ENOMEM);
	rules = kvmalloc_array(arg->rule_count, sizeof(*rules), GFP_KERNEL_ACCOUNT);
	principals = kvmalloc_array(arg->principal_count, sizeof(*principals), GFP_KERNEL_ACCOUNT);
	if ((arg->rule_count && !rules) || (arg->principal_count && !principals))
		goto out_free;
	policy = ERR_PTR(-EFAULT);
	if (copy_from_user(rules, u64_to_user_ptr(arg->rules),
			   array_size(arg->rule_count, sizeof(*rules))) ||
	    copy_from_user(principals, u64_to_user_ptr(arg->principals),
			   array_size(arg->principal_count, sizeof(*principals))))
		goto out_free;
	policy = agnocast_policy_build(arg, rules, principals);
out_free:
	kvfree(principals);
	kvfree(rules);
	return policy;
}

int agnocast_set_policy(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_policy_state *policy = NULL, *old;
	struct agnocast_policy arg;
	struct agnocast_ctx ctx;
	int ret;

	if (!ns_capable(current->nsproxy->ipc_ns->user_ns, CAP_SYS_ADMIN))
		return -EPERM;
	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.flags & ~(AGNOCAST_POLICY_PRESENT | AGNOCAST_POLICY_DEFAULT_DENY))
		return -EINVAL;
	if (arg.flags & AGNOCAST_POLICY_PRESENT) {
		policy = agnocast_policy_in(&arg);
		if (IS_ERR(policy))
			return PTR_ERR(policy);
	} else if (arg.flags || arg.rule_count || arg.principal_count || arg.reserved) {
		return -EINVAL;
	}

	ret = agnocast_enter_ns_write(&ctx, file_ns);
	if (ret) {
		agnocast_policy_free(policy);
		return ret;
	}
	old = ctx.ns->policy;
	ctx.ns->policy = policy;
	agnocast_leave(&ctx);
	agnocast_policy_free(old);
	return 0;
}

int agnocast_get_policy(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_policy_copy copy;
	struct agnocast_policy arg;
	struct agnocast_ctx ctx;
	u32 rule_capacity, principal_capacity;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.reserved || arg.flags)
		return -EINVAL;
	rule_capacity = arg.rule_count;
	principal_capacity = arg.principal_count;

	ret = agnocast_enter_ns_read(&ctx, file_ns);
	if (ret)
		return ret;
	ret = agnocast_policy_snapshot(ctx.ns->policy, &copy);
	agnocast_leave(&ctx);
	if (ret)
		goto out_free;

	arg.flags = copy.flags;
	arg.rule_count = copy.nr_rules;
	arg.principal_count = copy.nr_principals;
	ret = -EFAULT;
	if (copy_to_user(uarg, &arg, sizeof(arg)))
		goto out_free;
	ret = -ENOSPC;
	if (copy.nr_rules > rule_capacity || copy.nr_principals > principal_capacity)
		goto out_free;
	ret = -EFAULT;
	if (copy_to_user(u64_to_user_ptr(arg.rules), copy.rules,
			 array_size(copy.nr_rules, sizeof(*copy.rules))) ||
	    copy_to_user(u64_to_user_ptr(arg.principals), copy.principals,
			 array_size(copy.nr_principals, sizeof(*copy.principals))))
		goto out_free;
	ret = 0;
out_free:
	agnocast_policy_copy_free(&copy);
	return ret;
}
