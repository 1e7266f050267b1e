// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: read-only views of a namespace for the CLI and the daemon.
 *
 * These calls need no registration.  Pids are reported as the caller's pid
 * namespace sees them (0 when it cannot see the process), uids as its user
 * namespace does.  Each call builds its answer in kernel memory under the
 * namespace lock (agnocast_ns.lock) and copies it out after dropping it.
 */
#include <linux/bitmap.h>
#include <linux/cred.h>
#include <linux/mm.h>
#include <linux/overflow.h>
#include <linux/pid.h>
#include <linux/pid_namespace.h>
#include <linux/sched.h>
#include <linux/slab.h>
#include <linux/sort.h>
#include <linux/string.h>
#include <linux/uaccess.h>

#include "agnocast_internal.h"

static int agnocast_topic_cmp(const void *a, const void *b)
{
	const struct agnocast_topic *const *ta = a, *const *tb = b;

	return strcmp((*ta)->name, (*tb)->name);
}

int agnocast_list_topics(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_topic_summary *summaries = NULL;
	struct agnocast_topic **topics = NULL;
	struct agnocast_list_topics arg;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	u32 total = 0, n, i;
	int bkt, ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.flags || arg.reserved)
		return -EINVAL;
	ret = agnocast_enter_ns_read(&ctx, file_ns);
	if (ret)
		return ret;

	ret = -ENOMEM;
	if (ctx.ns->nr_topics) {
		topics = kvmalloc_array(ctx.ns->nr_topics, sizeof(*topics), GFP_KERNEL_ACCOUNT);
		if (!topics)
			goto out_leave;
	}
	hash_for_each(ctx.ns->topics, bkt, topic, hash_node) {
		if (topic->nr_publishers || topic->nr_subscribers)
			topics[total++] = topic;
	}
	sort(topics, total, sizeof(*topics), agnocast_topic_cmp, NULL);

	n = min(total, arg.capacity);
	if (n) {
		summaries = kvcalloc(n, sizeof(*summaries), GFP_KERNEL_ACCOUNT);
		if (!summaries)
			goto out_free;
	}
	for (i = 0; i < n; i++) {
		memcpy(summaries[i].name, topics[i]->name, sizeof(summaries[i].name));
		memcpy(summaries[i].type_name, topics[i]->type_name, sizeof(summaries[i].type_name));
		summaries[i].type_hash = topics[i]->type_hash;
		summaries[i].publishers = topics[i]->nr_publishers;
		summaries[i].subscribers = topics[i]->nr_subscribers;
	}
	arg.total = total;
	agnocast_leave(&ctx);
	ret = 0;
	if (copy_to_user(u64_to_user_ptr(arg.topics), summaries, array_size(n, sizeof(*summaries))) ||
	    copy_to_user(uarg, &arg, sizeof(arg)))
		ret = -EFAULT;
	kvfree(summaries);
	kvfree(topics);
	return ret;

out_free:
	kvfree(summaries);
	kvfree(topics);
out_leave:
	agnocast_leave(&ctx);
	return ret;
}

static void agnocast_publisher_info_fill(struct agnocast_publisher_info *out,
					 const struct agnocast_publisher *pub,
					 struct pid_namespace *pid_ns)
{
	memcpy(out->node, pub->ep.node, sizeof(out->node));
	out->id = pub->ep.id;
	out->pid = pid_nr_ns(pub->ep.proc->pid, pid_ns);
	out->depth = pub->ep.depth;
	out->flags = pub->ep.flags;
	out->published = pub->published;
	out->published_bytes = pub->published_bytes;
	out->window = pub->window_len;
	out->uid = from_kuid_munged(current_user_ns(), pub->ep.proc->uid);
}

static void agnocast_subscriber_info_fill(struct agnocast_subscriber_info *out,
					  const struct agnocast_subscriber *sub,
					  struct pid_namespace *pid_ns)
{
	memcpy(out->node, sub->ep.node, sizeof(out->node));
	out->id = sub->ep.id;
	out->pid = pid_nr_ns(sub->ep.proc->pid, pid_ns);
	out->depth = sub->ep.depth;
	out->flags = sub->ep.flags;
	out->unreceived = sub->nr_unreceived;
	out->held = sub->nr_held;
	out->received = sub->received;
	out->dropped = sub->dropped;
	out->uid = from_kuid_munged(current_user_ns(), sub->ep.proc->uid);
}

/* Answers of TOPIC_INFO, built under the namespace lock. */
struct agnocast_topic_answer {
	struct agnocast_publisher_info *pubs;
	struct agnocast_subscriber_info *subs;
	u32 npub;
	u32 nsub;
};

static int agnocast_topic_info_build(struct agnocast_ns *ns, struct agnocast_topic_info *arg,
				     struct agnocast_topic_answer *answer)
{
	struct pid_namespace *pid_ns = task_active_pid_ns(current);
	struct agnocast_endpoint *ep;
	struct agnocast_topic *topic;
	u32 i;

	lockdep_assert_held(&ns->lock);
	topic = agnocast_topic_find(ns, arg->name);
	if (!topic || !(topic->nr_publishers || topic->nr_subscribers))
		return -ENOENT;
	answer->npub = min(topic->nr_publishers, arg->publisher_capacity);
	answer->nsub = min(topic->nr_subscribers, arg->subscriber_capacity);
	answer->pubs = kvcalloc(answer->npub, sizeof(*answer->pubs), GFP_KERNEL_ACCOUNT);
	answer->subs = kvcalloc(answer->nsub, sizeof(*answer->subs), GFP_KERNEL_ACCOUNT);
	if ((answer->npub && !answer->pubs) || (answer->nsub && !answer->subs))
		return -ENOMEM;
	/* Counters and rings belong to the data path, under the topic's lock. */
	mutex_lock(&topic->lock);
	i = 0;
	list_for_each_entry(ep, &topic->publishers, topic_node) {
		if (i == answer->npub)
			break;
		agnocast_publisher_info_fill(&answer->pubs[i++], agnocast_to_publisher(ep), pid_ns);
	}
	i = 0;
	list_for_each_entry(ep, &topic->subscribers, topic_node) {
		if (i == answer->nsub)
			break;
		agnocast_subscriber_info_fill(&answer->subs[i++], agnocast_to_subscriber(ep),
					      pid_ns);
	}
	arg->publisher_total = topic->nr_publishers;
	arg->subscriber_total = topic->nr_subscribers;
	arg->entries = topic->nr_entries;
	mutex_unlock(&topic->lock);
	memcpy(arg->type_name, topic->type_name, sizeof(arg->type_name));
	arg->type_hash = topic->type_hash;
	arg->schema_size = topic->schema_size;
	return 0;
}

int agnocast_topic_info(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_topic_answer answer = {};
	struct agnocast_topic_info *arg;
	struct agnocast_ctx ctx;
	int ret;

	arg = memdup_user(uarg, sizeof(*arg));
	if (IS_ERR(arg))
		return PTR_ERR(arg);
	ret = -EINVAL;
	if (!memchr(arg->name, '\0', sizeof(arg->name)) || !agnocast_topic_name_valid(arg->name))
		goto out_free;
	ret = agnocast_enter_ns_read(&ctx, file_ns);
	if (ret)
		goto out_free;
	ret = agnocast_topic_info_build(ctx.ns, arg, &answer);
	agnocast_leave(&ctx);
	if (ret)
		goto out_free;

	if (copy_to_user(u64_to_user_ptr(arg->publishers), answer.pubs,
			 array_size(answer.npub, sizeof(*answer.pubs))) ||
	    copy_to_user(u64_to_user_ptr(arg->subscribers), answer.subs,
			 array_size(answer.nsub, sizeof(*answer.subs))) ||
	    copy_to_user(uarg, arg, sizeof(*arg)))
		ret = -EFAULT;
out_free:
	kvfree(answer.subs);
	kvfree(answer.pubs);
	kfree(arg);
	return ret;
}

static int agnocast_process_info_cmp(const void *a, const void *b)
{
	const struct agnocast_process_info *pa = a, *pb = b;

	return (pa->pid > pb->pid) - (pa->pid < pb->pid);
}

int agnocast_list_processes(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct pid_namespace *pid_ns = task_active_pid_ns(current);
	struct agnocast_process_info *infos = NULL;
	struct agnocast_list_processes arg;
	struct agnocast_proc *proc;
	struct agnocast_ctx ctx;
	u32 total, n, i = 0;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.flags || arg.reserved)
		return -EINVAL;
	ret = agnocast_enter_ns_read(&ctx, file_ns);
	if (ret)
		return ret;

	ret = -ENOMEM;
	total = ctx.ns->nr_procs;
	if (total) {
		infos = kvcalloc(total, sizeof(*infos), GFP_KERNEL_ACCOUNT);
		if (!infos)
			goto out_leave;
	}
	list_for_each_entry(proc, &ctx.ns->procs, ns_node) {
		struct agnocast_process_info *info = &infos[i++];

		info->pid = pid_nr_ns(proc->pid, pid_ns);
		info->publishers = proc->nr_publishers;
		info->subscribers = proc->nr_subscribers;
		info->pools_mapped = bitmap_weight(proc->given, agnocast_pool_count);
		info->pool_addr = proc->pool->addr;
		info->pool_size = proc->pool->size;
	}
	sort(infos, total, sizeof(*infos), agnocast_process_info_cmp, NULL);

	n = min(total, arg.capacity);
	arg.total = total;
	agnocast_leave(&ctx);
	ret = 0;
	if (copy_to_user(u64_to_user_ptr(arg.processes), infos, array_size(n, sizeof(*infos))) ||
	    copy_to_user(uarg, &arg, sizeof(arg)))
		ret = -EFAULT;
	kvfree(infos);
	return ret;

out_leave:
	agnocast_leave(&ctx);
	return ret;
}

int agnocast_topic_schema(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_topic_schema *arg;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	void *schema = NULL;
	int ret;

	arg = memdup_user(uarg, sizeof(*arg));
	if (IS_ERR(arg))
		return PTR_ERR(arg);
	ret = -EINVAL;
	if (!memchr(arg->name, '\0', sizeof(arg->name)) || !agnocast_topic_name_valid(arg->name))
		goto out_free_arg;
	ret = agnocast_enter_ns_read(&ctx, file_ns);
	if (ret)
		goto out_free_arg;
	topic = agnocast_topic_find(ctx.ns, arg->name);
	ret = -ENOENT;
	if (!topic || !(topic->nr_publishers || topic->nr_subscribers))
		goto out_leave;
	ret = -ENODATA;
	if (!topic->schema)
		goto out_leave;
	arg->size = topic->schema_size;
	ret = -ENOSPC;
	if (arg->capacity >= arg->size) {
		ret = -ENOMEM;
		schema = kvmalloc(topic->schema_size, GFP_KERNEL_ACCOUNT);
		if (schema) {
			memcpy(schema, topic->schema, topic->schema_size);
			ret = 0;
		}
	}
out_leave:
	agnocast_leave(&ctx);
	if (!ret && copy_to_user(u64_to_user_ptr(arg->schema), schema, arg->size))
		ret = -EFAULT;
	if ((!ret || ret == -ENOSPC) && copy_to_user(uarg, arg, sizeof(*arg)))
		ret = -EFAULT;
	kvfree(schema);
out_free_arg:
	kfree(arg);
	return ret;
}
