// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: read-only views of a namespace for the CLI and the daemon.
 *
 * These calls need no registration.  Pids are reported as the caller's pid
 * namespace sees them (0 when it cannot see the process).  Each call builds
 * its answer under the namespace lock (agnocast_ns.lock).
 */
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
	ret = agnocast_enter(&ctx, file_ns, false);
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
		summaries[i].publishers = topics[i]->nr_publishers;
		summaries[i].subscribers = topics[i]->nr_subscribers;
	}
	arg.total = total;
	ret = 0;
	if (copy_to_user(u64_to_user_ptr(arg.topics), summaries, array_size(n, sizeof(*summaries))) ||
	    copy_to_user(uarg, &arg, sizeof(arg)))
		ret = -EFAULT;
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
	memcpy(out->node, pub->node, sizeof(out->node));
	out->id = pub->id;
	out->pid = pid_nr_ns(pub->proc->pid, pid_ns);
	out->depth = pub->depth;
	out->flags = pub->flags;
	out->published = pub->published;
	out->published_bytes = pub->published_bytes;
	out->window = pub->window_len;
}

static void agnocast_subscriber_info_fill(struct agnocast_subscriber_info *out,
					  const struct agnocast_subscriber *sub,
					  struct pid_namespace *pid_ns)
{
	memcpy(out->node, sub->node, sizeof(out->node));
	out->id = sub->id;
	out->pid = pid_nr_ns(sub->proc->pid, pid_ns);
	out->depth = sub->depth;
	out->flags = sub->flags;
	out->unreceived = sub->nr_unreceived;
	out->held = sub->nr_held;
	out->received = sub->received;
	out->dropped = sub->dropped;
}

int agnocast_topic_info(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct pid_namespace *pid_ns = task_active_pid_ns(current);
	struct agnocast_subscriber_info *sub_infos = NULL;
	struct agnocast_publisher_info *pub_infos = NULL;
	struct agnocast_subscriber *sub;
	struct agnocast_publisher *pub;
	struct agnocast_topic_info *arg;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	u32 npub, nsub, i;
	int ret;

	arg = memdup_user(uarg, sizeof(*arg));
	if (IS_ERR(arg))
		return PTR_ERR(arg);
	ret = -EINVAL;
	if (arg->reserved || !memchr(arg->name, '\0', sizeof(arg->name)) ||
	    !agnocast_topic_name_valid(arg->name))
		goto out_free_arg;
	ret = agnocast_enter(&ctx, file_ns, false);
	if (ret)
		goto out_free_arg;

	ret = -ENOENT;
	topic = agnocast_topic_find(ctx.ns, arg->name);
	if (!topic || !(topic->nr_publishers || topic->nr_subscribers))
		goto out_leave;

	ret = -ENOMEM;
	npub = min(topic->nr_publishers, arg->publisher_capacity);
	nsub = min(topic->nr_subscribers, arg->subscriber_capacity);
	if (npub) {
		pub_infos = kvcalloc(npub, sizeof(*pub_infos), GFP_KERNEL_ACCOUNT);
		if (!pub_infos)
			goto out_free;
	}
	if (nsub) {
		sub_infos = kvcalloc(nsub, sizeof(*sub_infos), GFP_KERNEL_ACCOUNT);
		if (!sub_infos)
			goto out_free;
	}
	i = 0;
	list_for_each_entry(pub, &topic->publishers, topic_node) {
		if (i == npub)
			break;
		agnocast_publisher_info_fill(&pub_infos[i++], pub, pid_ns);
	}
	i = 0;
	list_for_each_entry(sub, &topic->subscribers, topic_node) {
		if (i == nsub)
			break;
		agnocast_subscriber_info_fill(&sub_infos[i++], sub, pid_ns);
	}
	arg->publisher_total = topic->nr_publishers;
	arg->subscriber_total = topic->nr_subscribers;
	arg->entries = topic->nr_entries;

	ret = 0;
	if (copy_to_user(u64_to_user_ptr(arg->publishers), pub_infos,
			 array_size(npub, sizeof(*pub_infos))) ||
	    copy_to_user(u64_to_user_ptr(arg->subscribers), sub_infos,
			 array_size(nsub, sizeof(*sub_infos))) ||
	    copy_to_user(uarg, arg, sizeof(*arg)))
		ret = -EFAULT;
out_free:
	kvfree(sub_infos);
	kvfree(pub_infos);
out_leave:
	agnocast_leave(&ctx);
out_free_arg:
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
	ret = agnocast_enter(&ctx, file_ns, false);
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
		info->pools_mapped = proc->nr_given;
		info->pool_addr = proc->pool->addr;
		info->pool_size = proc->pool->size;
	}
	sort(infos, total, sizeof(*infos), agnocast_process_info_cmp, NULL);

	n = min(total, arg.capacity);
	arg.total = total;
	ret = 0;
	if (copy_to_user(u64_to_user_ptr(arg.processes), infos, array_size(n, sizeof(*infos))) ||
	    copy_to_user(uarg, &arg, sizeof(arg)))
		ret = -EFAULT;
	kvfree(infos);
out_leave:
	agnocast_leave(&ctx);
	return ret;
}
