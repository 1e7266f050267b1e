// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: topics, id spaces, endpoints and message entries.
 *
 * A topic lives while it has an endpoint or an entry.  Its topic_local_ids
 * come from an id space shared by every topic whose name is equal once each
 * '/' after the first becomes '_' (the notification queue name); id spaces
 * outlive their topics for a while so that ids are not soon reused.
 *
 * An entry is referenced once while in its publisher's window and once per
 * subscriber that has it unreceived or held.  At zero it leaves the topic
 * and, if the pool's owner still lives, waits on the owner's reclaim list
 * until PUBLISH or RECLAIM hands its address back for reuse.
 *
 * Everything here is protected by the namespace lock (agnocast_ns.lock); see
 * agnocast_ns.c for the locking order.
 */
#include <linux/file.h>
#include <linux/jhash.h>
#include <linux/minmax.h>
#include <linux/slab.h>
#include <linux/string.h>
#include <linux/uaccess.h>

#include "agnocast_internal.h"

/* Entries (and pools) a RECEIVE handles without allocating; 4 keeps the frame small. */
#define AGNOCAST_RECEIVE_SMALL 4

static bool agnocast_str_terminated(const char *s, size_t size)
{
	return memchr(s, '\0', size) != NULL;
}

/* Starts with '/', [A-Za-z0-9_/], no "//", no trailing '/'. */
bool agnocast_topic_name_valid(const char *name)
{
	size_t i, len = strlen(name);

	if (len < 2 || name[0] != '/' || name[len - 1] == '/')
		return false;
	for (i = 1; i < len; i++) {
		char c = name[i];

		if (c == '/') {
			if (name[i - 1] == '/')
				return false;
		} else if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
			     (c >= '0' && c <= '9') || c == '_')) {
			return false;
		}
	}
	return true;
}

static bool agnocast_node_label_valid(const char *node)
{
	for (; *node; node++) {
		if (*node < 0x20 || *node > 0x7e)
			return false;
	}
	return true;
}

static u32 agnocast_name_hash(const char *name)
{
	return jhash(name, strlen(name), 0);
}

/* Id spaces. */

static struct agnocast_id_space *agnocast_id_space_get(struct agnocast_ns *ns,
						       const char *name)
{
	char mangled[AGNOCAST_TOPIC_NAME_MAX];
	struct agnocast_id_space *ids;
	size_t i;
	u32 hash;

	for (i = 0; name[i]; i++)
		mangled[i] = (i && name[i] == '/') ? '_' : name[i];
	mangled[i] = '\0';
	hash = agnocast_name_hash(mangled);

	hash_for_each_possible(ns->id_spaces, ids, hash_node, hash) {
		if (strcmp(ids->mangled, mangled))
			continue;
		if (!ids->topics++) {
			list_del_init(&ids->dormant_node);
			ns->nr_dormant_id_spaces--;
		}
		return ids;
	}

	ids = kzalloc(sizeof(*ids), GFP_KERNEL_ACCOUNT);
	if (!ids)
		return NULL;
	strscpy(ids->mangled, mangled, sizeof(ids->mangled));
	INIT_LIST_HEAD(&ids->dormant_node);
	ids->topics = 1;
	hash_add(ns->id_spaces, &ids->hash_node, hash);
	return ids;
}

static void agnocast_id_space_put(struct agnocast_ns *ns, struct agnocast_id_space *ids)
{
	if (--ids->topics)
		return;
	list_add_tail(&ids->dormant_node, &ns->dormant_id_spaces);
	if (++ns->nr_dormant_id_spaces <= AGNOCAST_DORMANT_ID_SPACES_MAX)
		return;
	ids = list_first_entry(&ns->dormant_id_spaces, struct agnocast_id_space,
			       dormant_node);
	list_del(&ids->dormant_node);
	hash_del(&ids->hash_node);
	kfree(ids);
	ns->nr_dormant_id_spaces--;
}

/* Namespace teardown: only dormant id spaces remain. */
void agnocast_id_spaces_free(struct agnocast_ns *ns)
{
	struct agnocast_id_space *ids;
	struct hlist_node *tmp;
	int bkt;

	hash_for_each_safe(ns->id_spaces, bkt, tmp, ids, hash_node) {
		hash_del(&ids->hash_node);
		kfree(ids);
	}
	INIT_LIST_HEAD(&ns->dormant_id_spaces);
	ns->nr_dormant_id_spaces = 0;
}

/* Topics. */

struct agnocast_topic *agnocast_topic_find(struct agnocast_ns *ns, const char *name)
{
	struct agnocast_topic *topic;

	lockdep_assert_held(&ns->lock);
	hash_for_each_possible(ns->topics, topic, hash_node, agnocast_name_hash(name)) {
		if (!strcmp(topic->name, name))
			return topic;
	}
	return NULL;
}

/* Printable ASCII (the type name may be empty). */
static bool agnocast_type_name_valid(const char *type_name)
{
	for (; *type_name; type_name++) {
		if (*type_name < 0x21 || *type_name > 0x7e)
			return false;
	}
	return true;
}

static struct agnocast_topic *agnocast_topic_get(struct agnocast_ns *ns, const char *name)
{
	struct agnocast_topic *topic;
	int handle;

	topic = agnocast_topic_find(ns, name);
	if (topic)
		return topic;
	if (ns->nr_topics >= agnocast_max_topics_per_namespace)
		return ERR_PTR(-ENFILE);

	topic = kzalloc(sizeof(*topic), GFP_KERNEL_ACCOUNT);
	if (!topic)
		return ERR_PTR(-ENOMEM);
	topic->ids = agnocast_id_space_get(ns, name);
	if (!topic->ids)
		goto err_free_topic;
	handle = idr_alloc_cyclic(&ns->topic_handles, topic, 1, 0, GFP_KERNEL_ACCOUNT);
	if (handle < 0)
		goto err_put_ids;

	topic->ns = ns;
	topic->handle = handle;
	strscpy(topic->name, name, sizeof(topic->name));
	INIT_LIST_HEAD(&topic->publishers);
	INIT_LIST_HEAD(&topic->subscribers);
	INIT_LIST_HEAD(&topic->entries);
	hash_add(ns->topics, &topic->hash_node, agnocast_name_hash(name));
	ns->nr_topics++;
	return topic;

err_put_ids:
	agnocast_id_space_put(ns, topic->ids);
err_free_topic:
	kfree(topic);
	return ERR_PTR(-ENOMEM);
}

static void agnocast_topic_maybe_free(struct agnocast_topic *topic)
{
	struct agnocast_ns *ns = topic->ns;

	lockdep_assert_held(&ns->lock);
	if (topic->nr_publishers || topic->nr_subscribers || topic->nr_entries)
		return;
	idr_remove(&ns->topic_handles, topic->handle);
	hash_del(&topic->hash_node);
	agnocast_id_space_put(ns, topic->ids);
	ns->nr_topics--;
	kvfree(topic->schema);
	kfree(topic);
}

static struct agnocast_topic *agnocast_topic_by_handle(struct agnocast_ns *ns, u32 handle)
{
	if (handle > INT_MAX)
		return NULL;
	return idr_find(&ns->topic_handles, handle);
}

/* Entries. */

static void agnocast_msg_unref(struct agnocast_msg *msg)
{
	struct agnocast_mempool *pool = msg->pool;
	struct agnocast_proc *owner = pool->owner;
	struct agnocast_topic *topic = msg->topic;

	lockdep_assert_held(&topic->ns->lock);
	if (WARN_ON_ONCE(!msg->refs) || --msg->refs)
		return;
	list_del(&msg->node);
	topic->nr_entries--;
	pool->entries--;
	if (owner) {
		list_add_tail(&msg->node, &owner->reclaim);
		owner->nr_reclaim++;
	} else {
		kfree(msg);
		agnocast_pool_maybe_free(topic->ns, pool);
	}
}

static void agnocast_msg_leave_window(struct agnocast_msg *msg)
{
	struct agnocast_publisher *pub = msg->publisher;

	list_del(&msg->window_node);
	pub->window_len--;
	msg->publisher = NULL;
	agnocast_msg_unref(msg);
}

static struct agnocast_msg *agnocast_sub_pop_oldest(struct agnocast_subscriber *sub)
{
	struct agnocast_msg *msg = sub->unreceived[sub->head];

	sub->head = (sub->head + 1) % sub->depth;
	sub->nr_unreceived--;
	return msg;
}

static struct agnocast_msg *agnocast_sub_unreceived(const struct agnocast_subscriber *sub,
						    u32 i)
{
	return sub->unreceived[(sub->head + i) % sub->depth];
}

/* Adds an unreceived reference; a full subscriber drops its oldest. */
static void agnocast_sub_push(struct agnocast_subscriber *sub, struct agnocast_msg *msg)
{
	if (sub->nr_unreceived == sub->depth) {
		agnocast_msg_unref(agnocast_sub_pop_oldest(sub));
		sub->dropped++;
	}
	sub->unreceived[(sub->head + sub->nr_unreceived) % sub->depth] = msg;
	sub->nr_unreceived++;
	msg->refs++;
}

/* AGNOCAST_IGNORE_LOCAL: the subscriber never gets its own process's entries. */
static bool agnocast_sub_ignores(const struct agnocast_subscriber *sub,
				 const struct agnocast_publisher *pub)
{
	return (sub->flags & AGNOCAST_IGNORE_LOCAL) && sub->proc == pub->proc;
}

/* Transient local: the newest entries still in transient-local windows. */
static void agnocast_sub_fill_transient(struct agnocast_subscriber *sub)
{
	struct agnocast_topic *topic = sub->topic;
	struct agnocast_msg *msg;
	u32 n = 0, i;

	list_for_each_entry_reverse(msg, &topic->entries, node) {
		if (n == sub->depth)
			break;
		if (msg->publisher && (msg->publisher->flags & AGNOCAST_TRANSIENT_LOCAL) &&
		    !agnocast_sub_ignores(sub, msg->publisher))
			n++;
	}
	i = n;
	list_for_each_entry_reverse(msg, &topic->entries, node) {
		if (!i)
			break;
		if (msg->publisher && (msg->publisher->flags & AGNOCAST_TRANSIENT_LOCAL) &&
		    !agnocast_sub_ignores(sub, msg->publisher)) {
			sub->unreceived[--i] = msg;
			msg->refs++;
		}
	}
	sub->head = 0;
	sub->nr_unreceived = n;
}

/* Endpoints. */

static void agnocast_publisher_destroy(struct agnocast_publisher *pub)
{
	while (!list_empty(&pub->window))
		agnocast_msg_leave_window(list_first_entry(&pub->window, struct agnocast_msg,
							   window_node));
	list_del(&pub->topic_node);
	list_del(&pub->proc_node);
	pub->topic->nr_publishers--;
	pub->proc->nr_publishers--;
	kfree(pub);
}

static void agnocast_subscriber_destroy(struct agnocast_subscriber *sub)
{
	struct agnocast_held *held, *tmp;

	while (sub->nr_unreceived)
		agnocast_msg_unref(agnocast_sub_pop_oldest(sub));
	list_for_each_entry_safe(held, tmp, &sub->held, node) {
		agnocast_msg_unref(held->entry);
		kfree(held);
	}
	list_del(&sub->topic_node);
	list_del(&sub->proc_node);
	sub->topic->nr_subscribers--;
	if (!(sub->flags & AGNOCAST_POLLING))
		sub->topic->nr_callback_subscribers--;
	sub->proc->nr_subscribers--;
	agnocast_exit_record_free(sub->exit_record);
	kvfree(sub->unreceived);
	kfree(sub);
}

void agnocast_proc_drop_endpoints(struct agnocast_proc *proc)
{
	struct agnocast_subscriber *sub, *stmp;
	struct agnocast_publisher *pub, *ptmp;
	struct agnocast_topic *topic;

	lockdep_assert_held(&proc->ns->lock);
	list_for_each_entry_safe(sub, stmp, &proc->subscribers, proc_node) {
		topic = sub->topic;
		agnocast_subscriber_destroy(sub);
		agnocast_topic_maybe_free(topic);
	}
	list_for_each_entry_safe(pub, ptmp, &proc->publishers, proc_node) {
		topic = pub->topic;
		agnocast_publisher_destroy(pub);
		agnocast_topic_maybe_free(topic);
	}
}

/* Frees the reclaim list and the spares. */
void agnocast_proc_drop_reclaim(struct agnocast_proc *proc)
{
	struct agnocast_held *held, *htmp;
	struct agnocast_msg *msg, *tmp;

	lockdep_assert_held(&proc->ns->lock);
	list_for_each_entry_safe(msg, tmp, &proc->reclaim, node)
		kfree(msg);
	INIT_LIST_HEAD(&proc->reclaim);
	proc->nr_reclaim = 0;
	list_for_each_entry_safe(msg, tmp, &proc->spare_msgs, node)
		kfree(msg);
	INIT_LIST_HEAD(&proc->spare_msgs);
	proc->nr_spare_msgs = 0;
	list_for_each_entry_safe(held, htmp, &proc->spare_held, node)
		kfree(held);
	INIT_LIST_HEAD(&proc->spare_held);
	proc->nr_spare_held = 0;
}

static int agnocast_publisher_lookup(struct agnocast_ctx *ctx, u32 handle, u32 id,
				     struct agnocast_publisher **out)
{
	struct agnocast_topic *topic = agnocast_topic_by_handle(ctx->ns, handle);
	struct agnocast_publisher *pub;

	if (!topic)
		return -ENOENT;
	list_for_each_entry(pub, &topic->publishers, topic_node) {
		if (pub->id != id)
			continue;
		if (pub->proc != ctx->proc)
			return -EPERM;
		*out = pub;
		return 0;
	}
	return -ENOENT;
}

static int agnocast_subscriber_lookup(struct agnocast_ctx *ctx, u32 handle, u32 id,
				      struct agnocast_subscriber **out)
{
	struct agnocast_topic *topic = agnocast_topic_by_handle(ctx->ns, handle);
	struct agnocast_subscriber *sub;

	if (!topic)
		return -ENOENT;
	list_for_each_entry(sub, &topic->subscribers, topic_node) {
		if (sub->id != id)
			continue;
		if (sub->proc != ctx->proc)
			return -EPERM;
		*out = sub;
		return 0;
	}
	return -ENOENT;
}

static bool agnocast_endpoint_args_valid(const struct agnocast_add_endpoint *arg,
					bool publisher)
{
	if (!agnocast_str_terminated(arg->topic, sizeof(arg->topic)) ||
	    !agnocast_topic_name_valid(arg->topic))
		return false;
	if (!agnocast_str_terminated(arg->node, sizeof(arg->node)) ||
	    !agnocast_node_label_valid(arg->node))
		return false;
	if (!arg->depth || arg->depth > AGNOCAST_DEPTH_MAX)
		return false;
	if (arg->flags & ~(AGNOCAST_TRANSIENT_LOCAL | AGNOCAST_POLLING | AGNOCAST_IGNORE_LOCAL))
		return false;
	if (!agnocast_str_terminated(arg->type_name, sizeof(arg->type_name)) ||
	    !agnocast_type_name_valid(arg->type_name))
		return false;
	if (arg->schema_size > AGNOCAST_SCHEMA_MAX || arg->reserved)
		return false;
	return !(publisher && (arg->flags & (AGNOCAST_POLLING | AGNOCAST_IGNORE_LOCAL)));
}

/*
 * A new topic takes the endpoint's type; an existing one must have it.  The
 * schema comes from the first endpoint that brings one (@schema is taken).
 */
static int agnocast_topic_type_check(struct agnocast_topic *topic,
				     const struct agnocast_add_endpoint *arg, void **schema)
{
	bool fresh = !topic->nr_publishers && !topic->nr_subscribers && !topic->nr_entries;

	if (fresh) {
		strscpy(topic->type_name, arg->type_name, sizeof(topic->type_name));
		topic->type_hash = arg->type_hash;
		kvfree(topic->schema);
		topic->schema = NULL;
		topic->schema_size = 0;
	} else if (topic->type_hash != arg->type_hash ||
		   strcmp(topic->type_name, arg->type_name)) {
		return -EPROTOTYPE;
	}
	if (!topic->schema && *schema) {
		topic->schema = *schema;
		topic->schema_size = arg->schema_size;
		*schema = NULL;
	}
	return 0;
}

static int agnocast_add_endpoint(struct agnocast_ns *file_ns, void __user *uarg,
				 bool publisher)
{
	struct agnocast_add_endpoint __user *uendpoint = uarg;
	struct agnocast_add_endpoint *arg;
	struct agnocast_subscriber *sub = NULL;
	struct agnocast_publisher *pub = NULL;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	void *schema = NULL;
	u32 id;
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

	ret = agnocast_enter(&ctx, file_ns, true);
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
	if (publisher) {
		pub = kzalloc(sizeof(*pub), GFP_KERNEL_ACCOUNT);
		if (!pub)
			goto out_put_topic;
	} else {
		sub = kzalloc(sizeof(*sub), GFP_KERNEL_ACCOUNT);
		if (!sub)
			goto out_put_topic;
		sub->unreceived = kvmalloc_array(arg->depth, sizeof(*sub->unreceived),
						 GFP_KERNEL_ACCOUNT);
		if (!sub->unreceived)
			goto out_free_sub;
		if (!(arg->flags & AGNOCAST_POLLING)) {
			sub->exit_record = agnocast_exit_record_alloc();
			if (!sub->exit_record)
				goto out_free_sub;
		}
	}

	/* Report before committing: a bad buffer must not leave an endpoint. */
	id = topic->ids->next_id;
	ret = -EFAULT;
	if (put_user(topic->handle, &uendpoint->topic_handle) || put_user(id, &uendpoint->id))
		goto out_free_sub;

	topic->ids->next_id++;
	if (publisher) {
		pub->topic = topic;
		pub->proc = ctx.proc;
		pub->id = id;
		pub->depth = arg->depth;
		pub->flags = arg->flags;
		INIT_LIST_HEAD(&pub->window);
		strscpy(pub->node, arg->node, sizeof(pub->node));
		list_add_tail(&pub->topic_node, &topic->publishers);
		list_add_tail(&pub->proc_node, &ctx.proc->publishers);
		topic->nr_publishers++;
		ctx.proc->nr_publishers++;
	} else {
		sub->topic = topic;
		sub->proc = ctx.proc;
		sub->id = id;
		sub->depth = arg->depth;
		sub->flags = arg->flags;
		INIT_LIST_HEAD(&sub->held);
		strscpy(sub->node, arg->node, sizeof(sub->node));
		if (sub->flags & AGNOCAST_TRANSIENT_LOCAL)
			agnocast_sub_fill_transient(sub);
		list_add_tail(&sub->topic_node, &topic->subscribers);
		list_add_tail(&sub->proc_node, &ctx.proc->subscribers);
		topic->nr_subscribers++;
		if (!(sub->flags & AGNOCAST_POLLING))
			topic->nr_callback_subscribers++;
		ctx.proc->nr_subscribers++;
	}
	ret = 0;
	goto out_leave;

out_free_sub:
	if (sub) {
		agnocast_exit_record_free(sub->exit_record);
		kvfree(sub->unreceived);
	}
	kfree(sub);
	kfree(pub);
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
	struct agnocast_subscriber *sub;
	struct agnocast_publisher *pub;
	struct agnocast_topic *topic;
	struct agnocast_ctx ctx;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	if (publisher) {
		ret = agnocast_publisher_lookup(&ctx, arg.topic_handle, arg.id, &pub);
		if (!ret) {
			topic = pub->topic;
			agnocast_publisher_destroy(pub);
		}
	} else {
		ret = agnocast_subscriber_lookup(&ctx, arg.topic_handle, arg.id, &sub);
		if (!ret) {
			topic = sub->topic;
			agnocast_subscriber_destroy(sub);
		}
	}
	if (!ret)
		agnocast_topic_maybe_free(topic);
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

static struct agnocast_msg *agnocast_msg_alloc(struct agnocast_proc *proc)
{
	struct agnocast_msg *msg;

	lockdep_assert_held(&proc->ns->lock);
	if (list_empty(&proc->spare_msgs))
		return kzalloc(sizeof(*msg), GFP_KERNEL_ACCOUNT);
	msg = list_first_entry(&proc->spare_msgs, struct agnocast_msg, node);
	list_del(&msg->node);
	proc->nr_spare_msgs--;
	memset(msg, 0, sizeof(*msg));
	return msg;
}

/* Keeps @node on @spares for reuse unless @nr spares are kept already. */
static bool agnocast_spare_keep(struct list_head *node, struct list_head *spares,
				unsigned int *nr)
{
	if (*nr >= AGNOCAST_SPARES_MAX)
		return false;
	list_add(node, spares);
	(*nr)++;
	return true;
}

static void agnocast_msg_free(struct agnocast_proc *proc, struct agnocast_msg *msg)
{
	lockdep_assert_held(&proc->ns->lock);
	if (!agnocast_spare_keep(&msg->node, &proc->spare_msgs, &proc->nr_spare_msgs))
		kfree(msg);
}

/*
 * Writes up to @capacity reclaimable addresses to @ubuf and forgets them only
 * once all were written, so a bad buffer loses none.
 */
static int agnocast_reclaim_out(struct agnocast_proc *proc, u64 ubuf, u32 capacity,
				u32 *count, u32 *pending)
{
	u64 __user *out = u64_to_user_ptr(ubuf);
	struct agnocast_msg *msg, *tmp;
	u32 n = 0;

	lockdep_assert_held(&proc->ns->lock);
	list_for_each_entry(msg, &proc->reclaim, node) {
		if (n == capacity)
			break;
		if (put_user(msg->addr, out + n))
			return -EFAULT;
		n++;
	}
	*count = n;
	list_for_each_entry_safe(msg, tmp, &proc->reclaim, node) {
		if (!n--)
			break;
		list_del(&msg->node);
		proc->nr_reclaim--;
		agnocast_msg_free(proc, msg);
	}
	*pending = proc->nr_reclaim;
	return 0;
}

int agnocast_publish(struct agnocast_ns *file_ns, void __user *uarg)
{
	u32 __user *wake_ids;
	struct agnocast_publish arg;
	struct agnocast_subscriber *sub;
	struct agnocast_publisher *pub;
	struct agnocast_mempool *pool;
	struct agnocast_topic *topic;
	struct agnocast_msg *msg;
	struct agnocast_ctx ctx;
	u32 wake_count = 0;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.reserved)
		return -EINVAL;
	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	ret = agnocast_publisher_lookup(&ctx, arg.topic_handle, arg.publisher_id, &pub);
	if (ret)
		goto out_leave;
	topic = pub->topic;
	pool = ctx.proc->pool;
	ret = -EBUSY;
	if (!pool->file)
		goto out_leave;
	ret = -EFAULT;
	if (arg.addr < pool->addr || arg.addr - pool->addr >= pool->size)
		goto out_leave;
	ret = -ENOBUFS;
	if (arg.wake_capacity < topic->nr_callback_subscribers)
		goto out_leave;

	ret = -ENOMEM;
	msg = agnocast_msg_alloc(ctx.proc);
	if (!msg)
		goto out_leave;

	/* The wake list is known before committing; write it first. */
	wake_ids = u64_to_user_ptr(arg.wake_ids);
	list_for_each_entry(sub, &topic->subscribers, topic_node) {
		if ((sub->flags & AGNOCAST_POLLING) || agnocast_sub_ignores(sub, pub))
			continue;
		if (put_user(sub->id, wake_ids + wake_count)) {
			agnocast_msg_free(ctx.proc, msg);
			ret = -EFAULT;
			goto out_leave;
		}
		wake_count++;
	}

	msg->topic = topic;
	msg->publisher = pub;
	msg->pool = pool;
	msg->id = topic->next_entry_id++;
	msg->addr = arg.addr;
	msg->publisher_id = pub->id;
	msg->refs = 1;
	list_add_tail(&msg->node, &topic->entries);
	topic->nr_entries++;
	pool->entries++;
	list_add_tail(&msg->window_node, &pub->window);
	pub->window_len++;
	pub->published++;
	pub->published_bytes += arg.bytes;
	list_for_each_entry(sub, &topic->subscribers, topic_node)
		if (!agnocast_sub_ignores(sub, pub))
			agnocast_sub_push(sub, msg);
	arg.entry_id = msg->id;
	if (pub->window_len > pub->depth)
		agnocast_msg_leave_window(list_first_entry(&pub->window, struct agnocast_msg,
							   window_node));

	arg.wake_count = wake_count;
	ret = agnocast_reclaim_out(ctx.proc, arg.reclaim, arg.reclaim_capacity,
				   &arg.reclaim_count, &arg.reclaim_pending);
out_leave:
	agnocast_leave(&ctx);
	if (ret)
		return ret;
	if (copy_to_user(uarg, &arg, sizeof(arg)))
		return -EFAULT;
	return 0;
}

int agnocast_reclaim(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_reclaim arg;
	struct agnocast_ctx ctx;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.reserved)
		return -EINVAL;
	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	ret = agnocast_reclaim_out(ctx.proc, arg.reclaim, arg.reclaim_capacity,
				   &arg.reclaim_count, &arg.reclaim_pending);
	agnocast_leave(&ctx);
	if (ret)
		return ret;
	if (copy_to_user(uarg, &arg, sizeof(arg)))
		return -EFAULT;
	return 0;
}

static void agnocast_held_free(struct agnocast_proc *proc, struct agnocast_held *held)
{
	lockdep_assert_held(&proc->ns->lock);
	if (!agnocast_spare_keep(&held->node, &proc->spare_held, &proc->nr_spare_held))
		kfree(held);
}

static void agnocast_held_free_list(struct agnocast_proc *proc, struct list_head *list)
{
	struct agnocast_held *held, *tmp;

	list_for_each_entry_safe(held, tmp, list, node) {
		list_del(&held->node);
		agnocast_held_free(proc, held);
	}
}

static int agnocast_held_alloc_list(struct agnocast_proc *proc, struct list_head *list, u32 n)
{
	struct agnocast_held *held;

	INIT_LIST_HEAD(list);
	for (; n && proc->nr_spare_held; n--) {
		held = list_first_entry(&proc->spare_held, struct agnocast_held, node);
		list_move(&held->node, list);
		proc->nr_spare_held--;
	}
	while (n--) {
		held = kzalloc(sizeof(*held), GFP_KERNEL_ACCOUNT);
		if (!held) {
			agnocast_held_free_list(proc, list);
			return -ENOMEM;
		}
		list_add(&held->node, list);
	}
	return 0;
}

static void agnocast_sub_hold(struct agnocast_subscriber *sub, struct list_head *spare,
			      struct agnocast_msg *msg)
{
	struct agnocast_held *held = list_first_entry(spare, struct agnocast_held, node);

	held->entry = msg;
	list_move_tail(&held->node, &sub->held);
	sub->nr_held++;
	sub->received++;
}

static void agnocast_entry_out(struct agnocast_entry *out, const struct agnocast_msg *msg)
{
	memset(out, 0, sizeof(*out));
	out->entry_id = msg->id;
	out->addr = msg->addr;
	out->publisher_id = msg->publisher_id;
}

int agnocast_receive(struct agnocast_ns *file_ns, void __user *uarg)
{
	/* A wake-up usually finds one entry: small receives need no allocation. */
	struct agnocast_mempool *pool_objs_small[AGNOCAST_RECEIVE_SMALL];
	struct agnocast_entry entries_small[AGNOCAST_RECEIVE_SMALL];
	struct agnocast_pool pools_small[AGNOCAST_RECEIVE_SMALL];
	struct agnocast_mempool **pool_objs = pool_objs_small;
	struct agnocast_entry *entries = entries_small;
	struct agnocast_pool *pools = pools_small;
	struct agnocast_subscriber *sub;
	struct agnocast_receive arg;
	struct agnocast_ctx ctx;
	u32 n, i, j, npools = 0, nfds = 0;
	LIST_HEAD(spare);
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	if (arg.reserved || !arg.entry_capacity || !arg.pool_capacity)
		return -EINVAL;
	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	ret = agnocast_subscriber_lookup(&ctx, arg.topic_handle, arg.subscriber_id, &sub);
	if (ret)
		goto out_leave;

	n = min(arg.entry_capacity, sub->nr_unreceived);
	ret = -EDQUOT;
	if (sub->nr_held >= agnocast_max_held_per_subscriber) {
		if (n)
			goto out_leave;
	} else {
		n = min(n, agnocast_max_held_per_subscriber - sub->nr_held);
	}
	ret = -ENOMEM;
	if (n > AGNOCAST_RECEIVE_SMALL) {
		entries = kvmalloc_array(n, sizeof(*entries), GFP_KERNEL_ACCOUNT);
		pools = kvmalloc_array(min(n, arg.pool_capacity), sizeof(*pools), GFP_KERNEL_ACCOUNT);
		pool_objs = kvmalloc_array(min(n, arg.pool_capacity), sizeof(*pool_objs),
					   GFP_KERNEL_ACCOUNT);
		if (!entries || !pools || !pool_objs)
			goto out_free;
	}

	/* Oldest first; stop at an entry whose pool does not fit in pools[]. */
	for (i = 0; i < n; i++) {
		struct agnocast_msg *msg = agnocast_sub_unreceived(sub, i);

		if (agnocast_pool_needs_giving(ctx.proc, msg->pool)) {
			for (j = 0; j < npools && pool_objs[j] != msg->pool; j++)
				;
			if (j == npools) {
				if (npools == arg.pool_capacity)
					break;
				pool_objs[npools++] = msg->pool;
			}
		}
		agnocast_entry_out(&entries[i], msg);
	}
	n = i;
	ret = agnocast_held_alloc_list(ctx.proc, &spare, n);
	if (ret)
		goto out_free;

	for (nfds = 0; nfds < npools; nfds++) {
		ret = agnocast_pool_prepare(pool_objs[nfds], &pools[nfds]);
		if (ret)
			goto out_put_fds;
	}
	arg.entry_count = n;
	arg.pool_count = npools;
	arg.remaining = sub->nr_unreceived - n;
	ret = -EFAULT;
	if (copy_to_user(u64_to_user_ptr(arg.entries), entries, array_size(n, sizeof(*entries))) ||
	    copy_to_user(u64_to_user_ptr(arg.pools), pools, array_size(npools, sizeof(*pools))) ||
	    copy_to_user(uarg, &arg, sizeof(arg)))
		goto out_put_fds;

	/* Commit: nothing below can fail. */
	for (j = 0; j < npools; j++)
		agnocast_pool_hand_over(ctx.proc, pool_objs[j], pools[j].fd);
	for (i = 0; i < n; i++)
		agnocast_sub_hold(sub, &spare, agnocast_sub_pop_oldest(sub));
	ret = 0;
	goto out_free;

out_put_fds:
	for (j = 0; j < nfds; j++)
		put_unused_fd(pools[j].fd);
	agnocast_held_free_list(ctx.proc, &spare);
out_free:
	if (entries != entries_small) {
		kvfree(pool_objs);
		kvfree(pools);
		kvfree(entries);
	}
out_leave:
	agnocast_leave(&ctx);
	return ret;
}

int agnocast_take(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_subscriber *sub;
	struct agnocast_msg *msg = NULL;
	struct agnocast_take arg;
	struct agnocast_ctx ctx;
	bool give = false;
	LIST_HEAD(spare);
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	ret = agnocast_subscriber_lookup(&ctx, arg.topic_handle, arg.subscriber_id, &sub);
	if (ret)
		goto out_leave;

	memset(&arg.entry, 0, sizeof(arg.entry));
	memset(&arg.pool, 0, sizeof(arg.pool));
	arg.entry_count = 0;
	arg.pool_count = 0;
	if (sub->nr_unreceived) {
		ret = -EDQUOT;
		if (sub->nr_held >= agnocast_max_held_per_subscriber)
			goto out_leave;
		msg = agnocast_sub_unreceived(sub, sub->nr_unreceived - 1);
		ret = agnocast_held_alloc_list(ctx.proc, &spare, 1);
		if (ret)
			goto out_leave;
		give = agnocast_pool_needs_giving(ctx.proc, msg->pool);
		if (give) {
			ret = agnocast_pool_prepare(msg->pool, &arg.pool);
			if (ret)
				goto out_free_spare;
			arg.pool_count = 1;
		}
		agnocast_entry_out(&arg.entry, msg);
		arg.entry_count = 1;
	}
	ret = -EFAULT;
	if (copy_to_user(uarg, &arg, sizeof(arg)))
		goto out_put_fd;

	ret = 0;
	if (!msg)
		goto out_leave;
	/* Commit: older unreceived entries are passed over, not dropped. */
	if (give)
		agnocast_pool_hand_over(ctx.proc, msg->pool, arg.pool.fd);
	while (sub->nr_unreceived > 1)
		agnocast_msg_unref(agnocast_sub_pop_oldest(sub));
	agnocast_sub_hold(sub, &spare, agnocast_sub_pop_oldest(sub));
	goto out_leave;

out_put_fd:
	if (give)
		put_unused_fd(arg.pool.fd);
out_free_spare:
	agnocast_held_free_list(ctx.proc, &spare);
out_leave:
	agnocast_leave(&ctx);
	return ret;
}

int agnocast_release(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_subscriber *sub;
	struct agnocast_release arg;
	struct agnocast_held *held;
	struct agnocast_ctx ctx;
	int ret;

	if (copy_from_user(&arg, uarg, sizeof(arg)))
		return -EFAULT;
	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	ret = agnocast_subscriber_lookup(&ctx, arg.topic_handle, arg.subscriber_id, &sub);
	if (ret)
		goto out_leave;
	ret = -ENOENT;
	list_for_each_entry(held, &sub->held, node) {
		if (held->entry->id != arg.entry_id)
			continue;
		list_del(&held->node);
		sub->nr_held--;
		agnocast_msg_unref(held->entry);
		agnocast_held_free(ctx.proc, held);
		ret = 0;
		break;
	}
out_leave:
	agnocast_leave(&ctx);
	return ret;
}

/*
 * Takes from @sub's unreceived entries those of @pool that have left their
 * publisher's window; keeps the order of the rest.
 */
static u32 agnocast_sub_shed(struct agnocast_subscriber *sub, struct agnocast_mempool *pool)
{
	u32 i, kept = 0, shed = 0, n = sub->nr_unreceived;

	for (i = 0; i < n; i++) {
		struct agnocast_msg *msg = agnocast_sub_unreceived(sub, i);

		if (msg->pool == pool && !msg->publisher) {
			agnocast_msg_unref(msg);
			shed++;
			continue;
		}
		/* kept <= i: this slot was read already. */
		sub->unreceived[(sub->head + kept) % sub->depth] = msg;
		kept++;
	}
	sub->nr_unreceived = kept;
	sub->dropped += shed;
	return shed;
}

int agnocast_shed(struct agnocast_ns *file_ns, void __user *uarg)
{
	struct agnocast_subscriber *sub;
	struct agnocast_publisher *pub;
	struct agnocast_shed arg = {};
	struct agnocast_ctx ctx;
	int ret;

	ret = agnocast_enter(&ctx, file_ns, true);
	if (ret)
		return ret;
	list_for_each_entry(pub, &ctx.proc->publishers, proc_node) {
		list_for_each_entry(sub, &pub->topic->subscribers, topic_node)
			arg.shed += agnocast_sub_shed(sub, ctx.proc->pool);
	}
	arg.reclaimable = ctx.proc->nr_reclaim;
	agnocast_leave(&ctx);
	if (copy_to_user(uarg, &arg, sizeof(arg)))
		return -EFAULT;
	return 0;
}
