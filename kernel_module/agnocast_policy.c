// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: the topic access policy of an IPC namespace (SET_POLICY,
 * GET_POLICY), checked when an endpoint is created.
 *
 * A new policy is copied in and validated before any lock is taken, then
 * swapped in under the namespace lock; GET_POLICY copies it out only after
 * dropping that lock.  Ids are stored as kernel ids, translated from and to
 * the caller's user namespace.  Existing endpoints are never re-checked.
 *
 * ns->policy is protected by the namespace lock (agnocast_ns.lock).
 */
#include <linux/capability.h>
#include <linux/cred.h>
#include <linux/ipc_namespace.h>
#include <linux/mm.h>
#include <linux/nsproxy.h>
#include <linux/overflow.h>
#include <linux/slab.h>
#include <linux/string.h>
#include <linux/uaccess.h>
#include <linux/uidgid.h>

#include "agnocast_internal.h"

struct agnocast_policy_principal_k {
	u32 kind;
	kuid_t uid;
	kgid_t gid;
};

struct agnocast_policy_rule_k {
	char prefix[AGNOCAST_TOPIC_NAME_MAX];
	size_t prefix_len;
	u32 match;
	u32 flags;
	u32 first_principal;
	u32 publish_count;
	u32 subscribe_count;
};

struct agnocast_policy_state {
	u32 flags;
	u32 nr_rules;
	u32 nr_principals;
	struct agnocast_policy_rule_k *rules;
	struct agnocast_policy_principal_k *principals;
};

void agnocast_policy_free(struct agnocast_policy_state *policy)
{
	if (!policy)
		return;
	kvfree(policy->principals);
	kvfree(policy->rules);
	kfree(policy);
}

static bool agnocast_rule_matches(const struct agnocast_policy_rule_k *rule, const char *topic)
{
	const char *rest;

	if (rule->match == AGNOCAST_MATCH_EXACT)
		return !strcmp(topic, rule->prefix);
	if (strncmp(topic, rule->prefix, rule->prefix_len) || topic[rule->prefix_len] != '/')
		return false;
	rest = topic + rule->prefix_len + 1;
	if (!*rest)
		return false;
	return rule->match == AGNOCAST_MATCH_DESCENDANTS || !strchr(rest, '/');
}

static bool agnocast_principal_matches(const struct agnocast_policy_principal_k *principal)
{
	switch (principal->kind) {
	case AGNOCAST_PRINCIPAL_ANYONE:
		return true;
	case AGNOCAST_PRINCIPAL_USER:
		return uid_eq(current_fsuid(), principal->uid);
	case AGNOCAST_PRINCIPAL_GROUP:
		return in_group_p(principal->gid);
	}
	return false;
}

/* 0 when the caller may create this endpoint, else -EACCES. */
int agnocast_policy_check(const struct agnocast_ns *ns, const char *topic, bool publisher)
{
	const struct agnocast_policy_state *policy = ns->policy;
	u32 direction = publisher ? AGNOCAST_RULE_PUBLISH : AGNOCAST_RULE_SUBSCRIBE;
	const struct agnocast_policy_rule_k *rule;
	u32 first, count, i, r;

	lockdep_assert_held(&ns->lock);
	if (!policy)
		return 0;
	for (r = 0; r < policy->nr_rules; r++) {
		rule = &policy->rules[r];
		if (!agnocast_rule_matches(rule, topic))
			continue;
		if (!(rule->flags & direction))
			break;
		first = rule->first_principal + (publisher ? 0 : rule->publish_count);
		count = publisher ? rule->publish_count : rule->subscribe_count;
		for (i = 0; i < count; i++) {
			if (agnocast_principal_matches(&policy->principals[first + i]))
				return 0;
		}
		return -EACCES;
	}
	return (policy->flags & AGNOCAST_POLICY_DEFAULT_DENY) ? -EACCES : 0;
}

static int agnocast_rule_in(struct agnocast_policy_rule_k *out,
			    const struct agnocast_policy_rule *in, u32 nr_principals)
{
	u64 end;

	if (in->reserved || in->flags & ~(AGNOCAST_RULE_PUBLISH | AGNOCAST_RULE_SUBSCRIBE))
		return -EINVAL;
	if (in->match > AGNOCAST_MATCH_DESCENDANTS)
		return -EINVAL;
	if (strnlen(in->prefix, sizeof(in->prefix)) == sizeof(in->prefix))
		return -EINVAL;
	/* Only "/ *" and "/ **" may stand for the root (an empty prefix). */
	if (in->prefix[0] ? !agnocast_topic_name_valid(in->prefix) :
			    in->match == AGNOCAST_MATCH_EXACT)
		return -EINVAL;
	if ((!(in->flags & AGNOCAST_RULE_PUBLISH) && in->publish_count) ||
	    (!(in->flags & AGNOCAST_RULE_SUBSCRIBE) && in->subscribe_count))
		return -EINVAL;
	end = (u64)in->first_principal + in->publish_count + in->subscribe_count;
	if (end > nr_principals)
		return -EINVAL;

	strscpy(out->prefix, in->prefix, sizeof(out->prefix));
	out->prefix_len = strlen(out->prefix);
	out->match = in->match;
	out->flags = in->flags;
	out->first_principal = in->first_principal;
	out->publish_count = in->publish_count;
	out->subscribe_count = in->subscribe_count;
	return 0;
}

static int agnocast_principal_in(struct agnocast_policy_principal_k *out,
				 const struct agnocast_principal *in)
{
	out->kind = in->kind;
	switch (in->kind) {
	case AGNOCAST_PRINCIPAL_ANYONE:
		return in->id ? -EINVAL : 0;
	case AGNOCAST_PRINCIPAL_USER:
		out->uid = make_kuid(current_user_ns(), in->id);
		return uid_valid(out->uid) ? 0 : -EINVAL;
	case AGNOCAST_PRINCIPAL_GROUP:
		out->gid = make_kgid(current_user_ns(), in->id);
		return gid_valid(out->gid) ? 0 : -EINVAL;
	}
	return -EINVAL;
}

/* Copies a policy in from user space and validates it; no lock held. */
static struct agnocast_policy_state *agnocast_policy_copy_in(const struct agnocast_policy *arg)
{
	struct agnocast_principal *principals = NULL;
	struct agnocast_policy_rule *rules = NULL;
	struct agnocast_policy_state *policy;
	int ret = -EINVAL;
	u32 i;

	if (arg->reserved || arg->rule_count > AGNOCAST_POLICY_RULES_MAX ||
	    arg->principal_count > AGNOCAST_POLICY_PRINCIPALS_MAX)
		return ERR_PTR(-EINVAL);
	policy = kzalloc(sizeof(*policy), GFP_KERNEL_ACCOUNT);
	if (!policy)
		return ERR_PTR(-ENOMEM);
	policy->flags = arg->flags;
	policy->nr_rules = arg->rule_count;
	policy->nr_principals = arg->principal_count;
	policy->rules = kvcalloc(arg->rule_count, sizeof(*policy->rules), GFP_KERNEL_ACCOUNT);
	policy->principals = kvcalloc(arg->principal_count, sizeof(*policy->principals),
				      GFP_KERNEL_ACCOUNT);
	if ((arg->rule_count && !policy->rules) || (arg->principal_count && !policy->principals)) {
		ret = -ENOMEM;
		goto err_free;
	}

	rules = kvmalloc_array(arg->rule_count, sizeof(*rules), GFP_KERNEL_ACCOUNT);
	principals = kvmalloc_array(arg->principal_count, sizeof(*principals), GFP_KERNEL_ACCOUNT);
	if ((arg->rule_count && !rules) || (arg->principal_count && !principals)) {
		ret = -ENOMEM;
		goto err_free;
	}
	ret = -EFAULT;
	if (copy_from_user(rules, u64_to_user_ptr(arg->rules),
			   array_size(arg->rule_count, sizeof(*rules))) ||
	    copy_from_user(principals, u64_to_user_ptr(arg->principals),
			   array_size(arg->principal_count, sizeof(*principals))))
		goto err_free;

	for (i = 0; i < arg->rule_count; i++) {
		ret = agnocast_rule_in(&policy->rules[i], &rules[i], arg->principal_count);
		if (ret)
			goto err_free;
	}
	for (i = 0; i < arg->principal_count; i++) {
		ret = agnocast_principal_in(&policy->principals[i], &principals[i]);
		if (ret)
			goto err_free;
	}
	kvfree(principals);
	kvfree(rules);
	return policy;

err_free:
	kvfree(principals);
	kvfree(rules);
	agnocast_policy_free(policy);
	return ERR_PTR(ret);
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
		policy = agnocast_policy_copy_in(&arg);
		if (IS_ERR(policy))
			return PTR_ERR(policy);
	} else if (arg.flags || arg.rule_count || arg.principal_count || arg.reserved) {
		return -EINVAL;
	}

	ret = agnocast_enter(&ctx, file_ns, false, true);
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

/* Snapshot of a policy in UAPI form, made under the namespace lock. */
struct agnocast_policy_copy {
	u32 flags;
	u32 nr_rules;
	u32 nr_principals;
	struct agnocast_policy_rule *rules;
	struct agnocast_principal *principals;
};

static int agnocast_policy_copy_out(const struct agnocast_policy_state *policy,
				    struct agnocast_policy_copy *copy)
{
	struct user_namespace *user_ns = current_user_ns();
	u32 i;

	memset(copy, 0, sizeof(*copy));
	if (!policy)
		return 0;
	copy->flags = policy->flags;
	copy->nr_rules = policy->nr_rules;
	copy->nr_principals = policy->nr_principals;
	copy->rules = kvcalloc(policy->nr_rules, sizeof(*copy->rules), GFP_KERNEL_ACCOUNT);
	copy->principals = kvcalloc(policy->nr_principals, sizeof(*copy->principals), GFP_KERNEL_ACCOUNT);
	if ((policy->nr_rules && !copy->rules) || (policy->nr_principals && !copy->principals))
		return -ENOMEM;
	for (i = 0; i < policy->nr_rules; i++) {
		const struct agnocast_policy_rule_k *rule = &policy->rules[i];

		strscpy(copy->rules[i].prefix, rule->prefix, sizeof(copy->rules[i].prefix));
		copy->rules[i].match = rule->match;
		copy->rules[i].flags = rule->flags;
		copy->rules[i].first_principal = rule->first_principal;
		copy->rules[i].publish_count = rule->publish_count;
		copy->rules[i].subscribe_count = rule->subscribe_count;
	}
	for (i = 0; i < policy->nr_principals; i++) {
		const struct agnocast_policy_principal_k *principal = &policy->principals[i];

		copy->principals[i].kind = principal->kind;
		if (principal->kind == AGNOCAST_PRINCIPAL_USER)
			copy->principals[i].id = from_kuid_munged(user_ns, principal->uid);
		else if (principal->kind == AGNOCAST_PRINCIPAL_GROUP)
			copy->principals[i].id = from_kgid_munged(user_ns, principal->gid);
	}
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

	ret = agnocast_enter(&ctx, file_ns, false, false);
	if (ret)
		return ret;
	ret = agnocast_policy_copy_out(ctx.ns->policy, &copy);
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
	kvfree(copy.principals);
	kvfree(copy.rules);
	return ret;
}
