// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: the endpoint and data-path commands.
 *
 * Each handler copies its argument in, enters the call context
 * (agnocast_call.c), calls down into topics (agnocast_topic.c), access
 * grants (agnocast_grant.c) and the entry engine (agnocast_entry.c), which
 * makes every per-message decision, leaves, and copies the answer out.
 * Nothing below calls back here.
 */
#include <linux/minmax.h>
#include <linux/slab.h>
#include <linux/string.h>
#include <linux/uaccess.h>

#include "agnocast_internal.h"

/* Entries a RECEIVE handles without allocating (the UAPI's batch). */
#define AGNOCAST_RECEIVE_SMALL AGNOCAST_RECEIVE_BATCH
/* Subscribers a PUBLISH wakes without allocating. */
#define AGNOCAST_WAKE_SMALL 16
/* Entry ids a RELEASE or RECEIVE releases without allocating. */
#define AGNOCAST_RELEASE_SMALL AGNOCAST_RECEIVE_BATCH
#define AGNOCAST_PUBLISH_FLAGS (AGNOCAST_PUBLISH_TO_ONE | AGNOCAST_PUBLISH_NO_DROP)

static int agnocast_add_endpoint(struct agnocast_ns *file_ns, void __user *uarg,
				 bool publisher)
{
	struct agnocast_add_endpoint __user *uendpoint = uarg;
	struct agnocast_add_endpoint *arg;
	struct agnocast_endpoint *ep;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	void *schema = NULL;
	int ret;

	arg = memdup_user(uarg, sizeof(*arg));
	if (IS_ERR(arg))
		return PTR_ERR(arg);
	ret = -EINVAL;
	if (!agnocast_endpoint_args_valid(arg, publisher))
		goto out_free_arg;
	if (arg->schema_size) {
		schema = kvmalloc(arg->schema_size, GFP_KERNEL_ACCOUNT);
		ret = -ENOMEM;
		if (!schema)
			goto out_free_arg;
		ret = -EFAULT;
		if (copy_from_user(schema, u64_to_user_ptr(arg->schema), arg->schema_size))
			goto out_free_arg;
	}

	ret = agnocast_enter_write(&ctx, file_ns);
	if (ret)
		goto out_free_arg;
	ret = agnocast_policy_check(ctx.ns, arg->topic, publisher);
	if (ret)
		goto out_leave;
	ret = -EMFILE;
	if (ctx.proc->nr_publishers + ctx.proc->nr_subscribers >=
	    agnocast_max_endpoints_per_process)
		goto out_leave;
	topic = agnocast_topic_get(ctx.ns, arg->topic);
	if (IS_ERR(topic)) {
		ret = PTR_ERR(topic);
		goto out_leave;
	}
	ret = agnocast_topic_type_check(topic, arg, &schema);
	if (ret)
		goto out_put_topic;
	ret = -ENOSPC;
	if (publisher ? topic->nr_publishers >= AGNOCAST_PUBLISHERS_PER_TOPIC_MAX :
			topic->nr_subscribers >= AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX)
		goto out_put_topic;
	if (topic->ids->next_id == U32_MAX)
		goto out_put_topic;
	ret = -ENOMEM;
	ep = agnocast_endpoint_create(topic, ctx.proc, arg, publisher);
	if (!ep)
		goto out_put_topic;

	/* Report before committing: a bad buffer must not leave an endpoint. */
	ret = -EFAULT;
	if (put_user(topic->handle, &uendpoint->topic_handle) ||
	    put_user(ep->id, &uendpoint->id)) {
		agnocast_endpoint_abandon(ep);
		goto out_put_topic;
	}
	agnocast_endpoint_commit(ep);
	ret = 0;
	goto out_leave;

out_put_topic:
	agnocast_topic_maybe_free(topic);
out_leave:
	agnocast_leave(&ctx);
out_free_arg:
	kvfree(schema);
	kfree(arg);
	return ret;
}

int agnocast_add_publisher(struct agnocast_ns *file_ns, void __user *uarg)
{
	return agnocast_add_endpoint(file_ns, uarg, true);
}

int agnocast_add_subscriber(struct agnocast_ns *file_ns, void __user *uarg)
{
	return agnocast_add_endpoint(file_ns, uarg, false);
}

static int agnocast_remove_endpoint(struct agnocast_ns *file_ns, void __user *uarg,
				    bool publisher)
{
	struct agnocast_remove_endpoint arg;
	struct agnocast_endpoint *ep;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	ret = agnocast_enter_write(&ctx, file_ns);
	if (ret)
		return ret;
	ret = agnocast_endpoint_lookup(ctx.ns, ctx.proc, arg.topic_handle, arg.id, publisher, &ep);
	if (!ret) {
		topic = ep->topic;
		agnocast_endpoint_destroy(ep);
		agnocast_topic_maybe_free(topic);
	}
	agnocast_leave(&ctx);
	return ret;
}

int agnocast_remove_publisher(struct agnocast_ns *file_ns, void __user *uarg)
{
	return agnocast_remove_endpoint(file_ns, uarg, true);
}

int agnocast_remove_subscriber(struct agnocast_ns *file_ns, void __user *uarg)
{
	return agnocast_remove_endpoint(file_ns, uarg, false);
}


/* Probes a field of the argument for writing, keeping its value. */
#define agnocast_arg_writable(ufield, value) (put_user(value, ufield) ? -EFAULT : 0)

/*
 * Addresses whose copy-out failed go back to the caller's reclaim list, if
 * the caller is still registered with the pool they belong to.
 */
static void agnocast_reclaim_copy_out(struct agnocast_ns *file_ns, u64 ubuf, const u64 *addrs,
				      u32 n)
{
	struct agnocast_mempool *pool;
	struct agnocast_ctx ctx;

	if (!n || agnocast_answer_out(u64_to_user_ptr(ubuf), addrs, n * sizeof(*addrs)))
		return;
	if (agnocast_enter_read(&ctx, file_ns))
		return;
	pool = ctx.proc->pool;
	if (addrs[0] >= pool->addr && addrs[0] - pool->addr < pool->size)
		agnocast_reclaim_return(ctx.proc, addrs, n);
	agnocast_leave(&ctx);
}

int agnocast_publish(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_publish __user *upublish = uarg;
	u64 reclaim[AGNOCAST_RECLAIM_BATCH];
	u32 wake_small[AGNOCAST_WAKE_SMALL];
	struct agnocast_topic_entry *entry;
	struct agnocast_publish arg;
	struct agnocast_endpoint *ep, *to_ep;
	struct agnocast_subscriber *to = NULL;
	struct agnocast_publisher *pub;
	struct agnocast_mempool *pool;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	u32 *wake = wake_small;
	u32 wake_max, reclaim_max, wake_needed, wake_count = 0;
	int ret;

	if (agnocast_words_in(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.reserved || (arg.flags & ~AGNOCAST_PUBLISH_FLAGS) ||
	    (arg.to_subscriber && !(arg.flags & AGNOCAST_PUBLISH_TO_ONE)))
		return -EINVAL;
	wake_max = min_t(u32, arg.wake_capacity, AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX);
	reclaim_max = min_t(u32, arg.reclaim_capacity, AGNOCAST_RECLAIM_BATCH);
	if (agnocast_out_writable(arg.wake_ids, wake_max * sizeof(u32)) ||
	    agnocast_out_writable(arg.reclaim, reclaim_max * sizeof(u64)) ||
	    agnocast_arg_writable(&upublish->reserved, 0))
		return agnocast_unwritable(file_ns);

	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		return ret;
	ret = agnocast_endpoint_lookup(ctx.ns, ctx.proc, arg.topic_handle, arg.publisher_id,
				       true, &ep);
	if (ret)
		goto out_leave;
	pub = agnocast_to_publisher(ep);
	topic = ep->topic;
	pool = ctx.proc->pool;
	ret = -EBUSY;
	if (!pool->file)
		goto out_leave;
	ret = -EFAULT;
	if (arg.addr < pool->addr || arg.addr - pool->addr >= pool->size)
		goto out_leave;
	wake_needed = topic->nr_callback_subscribers;
	if (arg.flags & AGNOCAST_PUBLISH_TO_ONE) {
		ret = -EINVAL;
		if (ep->flags & AGNOCAST_TRANSIENT_LOCAL)
			goto out_leave;
		/* Endpoints come and go under the namespace lock held for write. */
		to_ep = xa_load(&topic->endpoints, arg.to_subscriber);
		ret = -ENXIO;
		if (!to_ep || to_ep->publisher || agnocast_sub_ignores(to_ep, pub))
			goto out_leave;
		to = agnocast_to_subscriber(to_ep);
		wake_needed = 1;
	}
	ret = -ENOBUFS;
	if (arg.wake_capacity < wake_needed)
		goto out_leave;
	ret = -ENOMEM;
	if (wake_needed > ARRAY_SIZE(wake_small)) {
		wake = kvmalloc_array(wake_needed, sizeof(*wake), GFP_KERNEL_ACCOUNT);
		if (!wake)
			goto out_leave;
	}
	entry = agnocast_proc_entry_alloc(ctx.proc);
	if (!entry)
		goto out_leave;

	mutex_lock(&topic->lock);
	if (arg.flags & AGNOCAST_PUBLISH_NO_DROP) {
		ret = agnocast_entry_admits(pub, to);
		if (ret) {
			mutex_unlock(&topic->lock);
			agnocast_entry_free(entry);
			goto out_leave;
		}
	}
	/* Committed: nothing below fails. */
	wake_count = agnocast_entry_publish(pub, to, entry, pool, arg.addr, arg.bytes, wake);
	arg.entry_id = entry->id;
	mutex_unlock(&topic->lock);
	arg.wake_count = wake_count;
	arg.reclaim_count = agnocast_reclaim_take(ctx.proc, reclaim, reclaim_max,
						  &arg.reclaim_pending);
	ret = 0;
out_leave:
	agnocast_leave(&ctx);
	if (!ret) {
		agnocast_reclaim_copy_out(file_ns, arg.reclaim, reclaim, arg.reclaim_count);
		if (agnocast_answer_out(u64_to_user_ptr(arg.wake_ids), wake,
					wake_count * sizeof(*wake)))
			agnocast_answer_out(uarg, &arg, sizeof(arg));
	}
	if (wake != wake_small)
		kvfree(wake);
	return ret;
}

int agnocast_notify_failed(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_notify_failed arg;
	struct agnocast_subscriber *sub;
	struct agnocast_endpoint *ep;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	int ret;

	if (agnocast_words_in(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.reserved)
		return -EINVAL;
	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		return ret;
	ret = agnocast_endpoint_lookup(ctx.ns, ctx.proc, arg.topic_handle, arg.publisher_id,
				       true, &ep);
	if (ret)
		goto out_leave;
	topic = ep->topic;
	/* Endpoints come and go under the namespace lock held for write. */
	ep = xa_load(&topic->endpoints, arg.subscriber_id);
	ret = -ENOENT;
	if (!ep || ep->publisher)
		goto out_leave;
	sub = agnocast_to_subscriber(ep);
	ret = 0;
	mutex_lock(&topic->lock);
	/* A subscriber that looked since needs nothing: it got the entries. */
	if (sub->notified)
		agnocast_wake_break(sub);
	mutex_unlock(&topic->lock);
out_leave:
	agnocast_leave(&ctx);
	return ret;
}

int agnocast_reclaim(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_reclaim __user *ureclaim = uarg;
	u64 reclaim[AGNOCAST_RECLAIM_BATCH];
	struct agnocast_reclaim arg;
	struct agnocast_ctx ctx;
	u32 reclaim_max;
	int ret;

	if (agnocast_words_in(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.reserved)
		return -EINVAL;
	reclaim_max = min_t(u32, arg.reclaim_capacity, AGNOCAST_RECLAIM_BATCH);
	if (agnocast_out_writable(arg.reclaim, reclaim_max * sizeof(u64)) ||
	    agnocast_arg_writable(&ureclaim->reserved, 0))
		return agnocast_unwritable(file_ns);
	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		return ret;
	arg.reclaim_count = agnocast_reclaim_take(ctx.proc, reclaim, reclaim_max,
						  &arg.reclaim_pending);
	agnocast_leave(&ctx);
	agnocast_reclaim_copy_out(file_ns, arg.reclaim, reclaim, arg.reclaim_count);
	agnocast_answer_out(uarg, &arg, sizeof(arg));
	return 0;
}

/*
 * Copies in the @count entry ids at @uids, into @small when they fit, else
 * into memory to kvfree() when *ids != small.
 */
static int agnocast_release_ids_in(u64 uids, u32 count, u64 *small, u64 **ids)
{
	*ids = small;
	if (count > AGNOCAST_RELEASE_MAX)
		return -EINVAL;
	if (count > AGNOCAST_RELEASE_SMALL) {
		*ids = kvmalloc_array(count, sizeof(u64), GFP_KERNEL_ACCOUNT);
		if (!*ids)
			return -ENOMEM;
	}
	if (agnocast_words_in(*ids, u64_to_user_ptr(uids), count * sizeof(u64))) {
		if (*ids != small)
			kvfree(*ids);
		*ids = small;
		return -EFAULT;
	}
	return 0;
}

int agnocast_receive(struct agnocast_ns *file_ns, void __user *uarg)
{
	/* A wake-up usually finds one entry: small receives need no allocation. */
	struct agnocast_entry entries_small[AGNOCAST_RECEIVE_SMALL];
	struct agnocast_receive __user *ureceive = uarg;
	struct agnocast_entry *entries = entries_small;
	u64 release_small[AGNOCAST_RELEASE_SMALL];
	u64 *release_ids;
	struct agnocast_grants grants = {};
	struct agnocast_subscriber *sub;
	struct agnocast_receive arg;
	struct agnocast_endpoint *ep;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	u32 n, i, entry_max, installed = 0;
	int ret;

	if (agnocast_words_in(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (!arg.entry_capacity || !arg.pool_capacity || arg.release_count > AGNOCAST_RELEASE_MAX)
		return -EINVAL;
	entry_max = min_t(u32, arg.entry_capacity, AGNOCAST_RECEIVE_ENTRIES_MAX);
	grants.capacity = min_t(u32, arg.pool_capacity, AGNOCAST_RECEIVE_POOLS_MAX);
	if (agnocast_out_writable(arg.entries, entry_max * sizeof(*entries)) ||
	    agnocast_out_writable(arg.pools, grants.capacity * sizeof(struct agnocast_pool)) ||
	    agnocast_arg_writable(&ureceive->release_count, arg.release_count))
		return agnocast_unwritable(file_ns);
	ret = agnocast_release_ids_in(arg.release_ids, arg.release_count, release_small,
				      &release_ids);
	if (ret)
		return ret;
	if (entry_max > ARRAY_SIZE(entries_small)) {
		ret = -ENOMEM;
		entries = kvmalloc_array(entry_max, sizeof(*entries), GFP_KERNEL_ACCOUNT);
		if (!entries)
			goto out_free_ids;
	}

relock:
	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		goto out_close;
	ret = agnocast_endpoint_lookup(ctx.ns, ctx.proc, arg.topic_handle, arg.subscriber_id,
				       false, &ep);
	if (ret)
		goto out_leave;
	sub = agnocast_to_subscriber(ep);
	topic = ep->topic;
	mutex_lock(&topic->lock);
	ret = agnocast_sub_receivable(sub, arg.release_count, entry_max, &n);
	if (ret)
		goto out_unlock;
	/* Oldest first; stop at an entry whose pool does not fit in the grants. */
	for (i = 0; i < n; i++) {
		struct agnocast_mempool *pool = agnocast_sub_unreceived(sub, i)->pool;

		if (!agnocast_grants_readable(ctx.proc, &grants, pool) &&
		    !agnocast_grants_add(&grants, pool))
			break;
	}
	n = i;
	if (grants.count > installed) {
		mutex_unlock(&topic->lock);
		agnocast_leave(&ctx);
		ret = agnocast_grants_install(&grants, installed);
		if (ret)
			goto out_close;
		installed = grants.count;
		goto relock;
	}
	ret = agnocast_sub_reserve_held(sub, n);
	if (ret)
		goto out_unlock;
	ret = agnocast_sub_release(sub, release_ids, arg.release_count);
	if (ret)
		goto out_unlock;

	/* Commit: nothing below fails. */
	agnocast_grants_commit(ctx.proc, &grants, sub, 0, n);
	agnocast_sub_receive(sub, entries, n);
	arg.entry_count = n;
	arg.pool_count = grants.count;
	arg.remaining = sub->nr_unreceived;
	mutex_unlock(&topic->lock);
	agnocast_leave(&ctx);
	if (agnocast_answer_out(u64_to_user_ptr(arg.entries), entries, n * sizeof(*entries)) &&
	    agnocast_answer_out(u64_to_user_ptr(arg.pools), grants.out,
				grants.count * sizeof(grants.out[0])))
		agnocast_answer_out(uarg, &arg, sizeof(arg));
	goto out_put;

out_unlock:
	mutex_unlock(&topic->lock);
out_leave:
	agnocast_leave(&ctx);
out_close:
	agnocast_grants_close(&grants);
out_put:
	agnocast_grants_put(&grants);
	if (entries != entries_small)
		kvfree(entries);
out_free_ids:
	if (release_ids != release_small)
		kvfree(release_ids);
	return ret;
}

/* Attempts of TAKE to catch a newest entry whose pool it has installed. */
#define AGNOCAST_TAKE_ATTEMPTS 4

int agnocast_take(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_take __user *utake = uarg;
	struct agnocast_grants grants = { .capacity = 1 };
	struct agnocast_topic_entry *entry;
	struct agnocast_subscriber *sub;
	struct agnocast_endpoint *ep;
	struct agnocast_topic *topic;
	struct agnocast_take arg;
	struct agnocast_ctx ctx;
	u32 attempts = 0;
	int ret;

	if (agnocast_words_in(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.flags || arg.reserved)
		return -EINVAL;
	if (agnocast_arg_writable(&utake->pool_count, arg.pool_count))
		return agnocast_unwritable(file_ns);

relock:
	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		goto out_close;
	ret = agnocast_endpoint_lookup(ctx.ns, ctx.proc, arg.topic_handle, arg.subscriber_id,
				       false, &ep);
	if (ret)
		goto out_leave;
	sub = agnocast_to_subscriber(ep);
	topic = ep->topic;
	memset(&arg.entry, 0, sizeof(arg.entry));
	memset(&arg.pool, 0, sizeof(arg.pool));
	arg.entry_count = 0;
	arg.pool_count = 0;
	mutex_lock(&topic->lock);
	if (sub->nr_unreceived) {
		ret = agnocast_sub_takeable(sub);
		if (ret)
			goto out_unlock;
		entry = agnocast_sub_unreceived(sub, sub->nr_unreceived - 1);
		if (!agnocast_grants_readable(ctx.proc, &grants, entry->pool)) {
			/* Install its pool, then look again: the newest may have moved. */
			ret = -EAGAIN;
			if (++attempts > AGNOCAST_TAKE_ATTEMPTS)
				goto out_unlock;
			agnocast_grants_add_over(&grants, entry->pool);
			mutex_unlock(&topic->lock);
			agnocast_leave(&ctx);
			ret = agnocast_grants_install(&grants, 0);
			if (ret)
				goto out_put;
			goto relock;
		}
		ret = agnocast_sub_reserve_held(sub, 1);
		if (ret)
			goto out_unlock;
		/* Commit: nothing below fails. */
		agnocast_grants_commit(ctx.proc, &grants, sub, sub->nr_unreceived - 1, 1);
		agnocast_sub_take_newest(sub, &arg.entry);
		arg.entry_count = 1;
	} else {
		/* What was installed for an entry that went since. */
		agnocast_grants_commit(ctx.proc, &grants, sub, 0, 0);
	}
	if (grants.count) {
		arg.pool = grants.out[0];
		arg.pool_count = 1;
	}
	mutex_unlock(&topic->lock);
	agnocast_leave(&ctx);
	agnocast_answer_out(uarg, &arg, sizeof(arg));
	ret = 0;
	goto out_put;

out_unlock:
	mutex_unlock(&topic->lock);
out_leave:
	agnocast_leave(&ctx);
out_close:
	agnocast_grants_close(&grants);
out_put:
	agnocast_grants_put(&grants);
	return ret;
}

int agnocast_release(struct agnocast_ns *file_ns, void __user *uarg)
{
	u64 ids_small[AGNOCAST_RELEASE_SMALL];
	struct agnocast_release arg;
	struct agnocast_endpoint *ep;
	struct agnocast_ctx ctx;
	u64 *ids;
	int ret;

	if (agnocast_words_in(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.flags || !arg.count)
		return -EINVAL;
	ret = agnocast_release_ids_in(arg.entry_ids, arg.count, ids_small, &ids);
	if (ret)
		return ret;
	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		goto out_free;
	ret = agnocast_endpoint_lookup(ctx.ns, ctx.proc, arg.topic_handle, arg.subscriber_id,
				       false, &ep);
	if (!ret) {
		mutex_lock(&ep->topic->lock);
		ret = agnocast_sub_release(agnocast_to_subscriber(ep), ids, arg.count);
		mutex_unlock(&ep->topic->lock);
	}
	agnocast_leave(&ctx);
out_free:
	if (ids != ids_small)
		kvfree(ids);
	return ret;
}

int agnocast_shed(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_shed arg = {};
	struct agnocast_ctx ctx;
	int ret;

	ret = agnocast_enter_read(&ctx, file_ns);
	if (ret)
		return ret;
	arg.shed = agnocast_proc_shed(ctx.proc, &arg.reclaimable);
	agnocast_leave(&ctx);
	if (copy_to_user(uarg, &arg, sizeof(arg)))
		return -EFAULT;
	return 0;
}
