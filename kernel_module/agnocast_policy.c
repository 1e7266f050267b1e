// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: the topic access policy of an IPC namespace: built from its UAPI
 * form, checked when an endpoint is created, snapshotted back to UAPI form.
 *
 * The SET_POLICY and GET_POLICY handlers (agnocast_admin.c) copy a policy in
 * and have it built and validated before any lock is taken, swap it in under
 * the namespace lock, and copy a snapshot out only after dropping that lock.
 * Ids are stored as kernel ids, translated from and to the caller's user
 * namespace.  Existing endpoints are never re-checked.  Nothing here touches
 * user memory.
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

/* Whether @arg's counts are within bounds: the caller may copy the arrays in. */
bool agnocast_policy_arg_valid(const struct agnocast_policy *arg)
{
	return !arg->reserved && arg->rule_count <= AGNOCAST_POLICY_RULES_MAX &&
	       arg->principal_count <= AGNOCAST_POLICY_PRINCIPALS_MAX;
}

/*
 * Builds a policy from its UAPI form (@arg, checked by
 * agnocast_policy_arg_valid(), and the arrays it counts, copied in by the
 * caller), validating every rule and principal; no lock held.
 */
struct agnocast_policy_state *agnocast_policy_build(const struct agnocast_policy *arg,
						    const struct agnocast_policy_rule *rules,
						    const struct agnocast_principal *principals)
{
	struct agnocast_policy_state *policy;
	int ret = -ENOMEM;
	u32 i;

	policy = kzalloc(sizeof(*policy), GFP_KERNEL_ACCOUNT);
	if (!policy)
		return ERR_PTR(-ENOMEM);
	policy->flags = arg->flags;
	policy->nr_rules = arg->rule_count;
	policy->nr_principals = arg->principal_count;
	policy->rules = kvcalloc(arg->rule_count, sizeof(*policy->rules), GFP_KERNEL_ACCOUNT);
	policy->principals = kvcalloc(arg->principal_count, sizeof(*policy->principals),
				      GFP_KERNEL_ACCOUNT);
	if ((arg->rule_count && !policy->rules) || (arg->principal_count && !policy->principals))
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
	return policy;

err_free:
	agnocast_policy_free(policy);
	return ERR_PTR(ret);
}

/*
 * Snapshots @policy in UAPI form, ids as the caller's user namespace sees
 * them (namespace lock held); agnocast_policy_copy_free() frees it.
 */
int agnocast_policy_snapshot(const struct agnocast_policy_state *policy,
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
	copy->principals = kvcalloc(policy->nr_principals, sizeof(*copy->principals),
				    GFP_KERNEL_ACCOUNT);
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

void agnocast_policy_copy_free(struct agnocast_policy_copy *copy)
{
	kvfree(copy->principals);
	kvfree(copy->rules);
}
