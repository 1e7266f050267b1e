// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: topics, id spaces and endpoints.
 *
 * A topic lives while it has an endpoint or an entry.  Its topic_local_ids
 * come from an id space shared by every topic whose name is equal once each
 * '/' after the first becomes '_' (the notification queue name); id spaces
 * outlive their topics for a while so that ids are not soon reused.
 *
 * Publishers and subscribers share one head, struct agnocast_endpoint, and
 * are found by id in the topic's xarray.  Adding one is two-phase
 * (agnocast_endpoint_create() reserves everything it needs, then
 * agnocast_endpoint_commit() cannot fail) so that an ioctl can report the id
 * before the endpoint exists.
 *
 * This file calls down into the entry engine only, never into ioctls.
 * Topics and endpoints change with the namespace lock (agnocast_ns.lock) held
 * for write and are looked up with it held at least for read; what the entry
 * engine keeps of a topic is under the topic's own lock.
 */
#include <linux/hash.h>
#include <linux/jhash.h>
#include <linux/log2.h>
#include <linux/minmax.h>
#include <linux/slab.h>
#include <linux/string.h>

#include "agnocast_internal.h"

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

struct agnocast_topic *agnocast_topic_get(struct agnocast_ns *ns, const char *name)
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
	xa_init(&topic->endpoints);
	mutex_init(&topic->lock);
	hash_add(ns->topics, &topic->hash_node, agnocast_name_hash(name));
	ns->nr_topics++;
	return topic;

err_put_ids:
	agnocast_id_space_put(ns, topic->ids);
err_free_topic:
	kfree(topic);
	return ERR_PTR(-ENOMEM);
}

void agnocast_topic_maybe_free(struct agnocast_topic *topic)
{
	struct agnocast_ns *ns = topic->ns;

	lockdep_assert_held_write(&ns->lock);
	if (topic->nr_publishers || topic->nr_subscribers || topic->nr_entries)
		return;
	idr_remove(&ns->topic_handles, topic->handle);
	hash_del(&topic->hash_node);
	agnocast_id_space_put(ns, topic->ids);
	ns->nr_topics--;
	xa_destroy(&topic->endpoints);
	mutex_destroy(&topic->lock);
	kvfree(topic->schema);
	kfree(topic);
}

static struct agnocast_topic *agnocast_topic_by_handle(struct agnocast_ns *ns, u32 handle)
{
	if (handle > INT_MAX)
		return NULL;
	return idr_find(&ns->topic_handles, handle);
}

bool agnocast_endpoint_args_valid(const struct agnocast_add_endpoint *arg, bool publisher)
{
	if (!agnocast_str_terminated(arg->topic, sizeof(arg->topic)) ||
	    !agnocast_topic_name_valid(arg->topic))
		return false;
	if (!agnocast_str_terminated(arg->node, sizeof(arg->node)) ||
	    !agnocast_node_label_valid(arg->node))
		return false;
	if (!arg->depth || arg->depth > AGNOCAST_DEPTH_MAX)
		return false;
	if (arg->flags & ~(AGNOCAST_TRANSIENT_LOCAL | AGNOCAST_POLLING | AGNOCAST_IGNORE_LOCAL |
			   AGNOCAST_WAKE_ONCE))
		return false;
	if ((arg->flags & AGNOCAST_WAKE_ONCE) && (arg->flags & AGNOCAST_POLLING))
		return false;
	if (!agnocast_str_terminated(arg->type_name, sizeof(arg->type_name)) ||
	    !agnocast_type_name_valid(arg->type_name))
		return false;
	if (arg->schema_size > AGNOCAST_SCHEMA_MAX || arg->reserved)
		return false;
	return !(publisher &&
		 (arg->flags & (AGNOCAST_POLLING | AGNOCAST_IGNORE_LOCAL | AGNOCAST_WAKE_ONCE)));
}

/*
 * A new topic takes the endpoint's type; an existing one must have it.  The
 * schema comes from the first endpoint that brings one (@schema is taken).
 */
int agnocast_topic_type_check(struct agnocast_topic *topic,
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

/* Endpoints. */

static void agnocast_endpoint_free(struct agnocast_endpoint *ep)
{
	struct agnocast_subscriber *sub;

	if (ep->publisher) {
		kfree(agnocast_to_publisher(ep));
		return;
	}
	sub = agnocast_to_subscriber(ep);
	agnocast_wake_sub_shutdown(sub);
	agnocast_exit_record_free(sub->exit_record);
	kvfree(sub->unreceived);
	kvfree(sub->held);
	kfree(sub);
}

/*
 * Allocates an endpoint of @topic for @proc with what it will need, and
 * reserves its id (ep->id) in the topic's xarray; not yet visible.
 */
struct agnocast_endpoint *agnocast_endpoint_create(struct agnocast_topic *topic,
						   struct agnocast_proc *proc,
						   const struct agnocast_add_endpoint *arg,
						   bool publisher)
{
	struct agnocast_subscriber *sub;
	struct agnocast_publisher *pub;
	struct agnocast_endpoint *ep;

	lockdep_assert_held_write(&topic->ns->lock);
	if (publisher) {
		pub = kzalloc(sizeof(*pub), GFP_KERNEL_ACCOUNT);
		if (!pub)
			return NULL;
		INIT_LIST_HEAD(&pub->window);
		ep = &pub->ep;
		ep->publisher = true;
	} else {
		sub = kzalloc(sizeof(*sub), GFP_KERNEL_ACCOUNT);
		if (!sub)
			return NULL;
		agnocast_wake_sub_init(sub);
		ep = &sub->ep;
		sub->unreceived = kvmalloc_array(arg->depth, sizeof(*sub->unreceived),
						 GFP_KERNEL_ACCOUNT);
		if (!sub->unreceived)
			goto err_free;
		/* A wake-up's entries, and those of the one before, still held. */
		sub->held_capacity = 2 * arg->depth;
		sub->held = kvmalloc_array(sub->held_capacity, sizeof(*sub->held),
					   GFP_KERNEL_ACCOUNT);
		if (!sub->held)
			goto err_free;
		if (!(arg->flags & AGNOCAST_POLLING)) {
			sub->exit_record = agnocast_exit_record_alloc();
			if (!sub->exit_record)
				goto err_free;
		}
	}
	ep->topic = topic;
	ep->proc = proc;
	ep->id = topic->ids->next_id;
	ep->depth = arg->depth;
	ep->flags = arg->flags;
	strscpy(ep->node, arg->node, sizeof(ep->node));
	if (xa_reserve(&topic->endpoints, ep->id, GFP_KERNEL_ACCOUNT))
		goto err_free;
	return ep;

err_free:
	agnocast_endpoint_free(ep);
	return NULL;
}

/* Undoes agnocast_endpoint_create(). */
void agnocast_endpoint_abandon(struct agnocast_endpoint *ep)
{
	xa_release(&ep->topic->endpoints, ep->id);
	agnocast_endpoint_free(ep);
}

/* Makes a created endpoint visible; cannot fail. */
void agnocast_endpoint_commit(struct agnocast_endpoint *ep)
{
	struct agnocast_topic *topic = ep->topic;
	struct agnocast_proc *proc = ep->proc;
	struct agnocast_subscriber *sub;

	lockdep_assert_held_write(&topic->ns->lock);
	topic->ids->next_id++;
	xa_store(&topic->endpoints, ep->id, ep, GFP_NOWAIT);
	if (ep->publisher) {
		list_add_tail(&ep->topic_node, &topic->publishers);
		list_add_tail(&ep->proc_node, &proc->publishers);
		topic->nr_publishers++;
		proc->nr_publishers++;
		return;
	}
	sub = agnocast_to_subscriber(ep);
	if (ep->flags & AGNOCAST_TRANSIENT_LOCAL) {
		mutex_lock(&topic->lock);
		agnocast_sub_fill_transient(sub);
		mutex_unlock(&topic->lock);
	}
	list_add_tail(&ep->topic_node, &topic->subscribers);
	list_add_tail(&ep->proc_node, &proc->subscribers);
	topic->nr_subscribers++;
	if (!(ep->flags & AGNOCAST_POLLING))
		topic->nr_callback_subscribers++;
	proc->nr_subscribers++;
}

/* Where @proc keeps its endpoint @id of topic @handle among its recent ones. */
static struct agnocast_endpoint **agnocast_endpoint_recent(struct agnocast_proc *proc,
							     u32 handle, u32 id)
{
	return &proc->recent_endpoints[hash_32(handle ^ (id << 16) ^ (id >> 16),
					       ilog2(AGNOCAST_RECENT_ENDPOINTS))];
}

/* Takes @ep out of its process's recent endpoints (lock held for write). */
static void agnocast_endpoint_forget(struct agnocast_endpoint *ep)
{
	struct agnocast_endpoint **recent = agnocast_endpoint_recent(ep->proc, ep->topic->handle,
								     ep->id);

	if (*recent == ep)
		*recent = NULL;
}

/* Drops the endpoint and its references; the caller frees the topic if idle. */
void agnocast_endpoint_destroy(struct agnocast_endpoint *ep)
{
	struct agnocast_topic *topic = ep->topic;
	struct agnocast_proc *proc = ep->proc;

	lockdep_assert_held_write(&topic->ns->lock);
	agnocast_endpoint_forget(ep);
	xa_erase(&topic->endpoints, ep->id);
	list_del(&ep->topic_node);
	list_del(&ep->proc_node);
	mutex_lock(&topic->lock);
	if (ep->publisher)
		agnocast_publisher_drop_window(agnocast_to_publisher(ep));
	else
		agnocast_sub_drop_entries(agnocast_to_subscriber(ep));
	mutex_unlock(&topic->lock);
	if (ep->publisher) {
		topic->nr_publishers--;
		proc->nr_publishers--;
	} else {
		topic->nr_subscribers--;
		if (!(ep->flags & AGNOCAST_POLLING))
			topic->nr_callback_subscribers--;
		proc->nr_subscribers--;
	}
	agnocast_endpoint_free(ep);
}

/* The caller's publisher or subscriber @id of the topic @handle. */
int agnocast_endpoint_lookup(struct agnocast_ns *ns, struct agnocast_proc *proc, u32 handle,
			     u32 id, bool publisher, struct agnocast_endpoint **out)
{
	struct agnocast_endpoint **recent = agnocast_endpoint_recent(proc, handle, id);
	struct agnocast_endpoint *ep = READ_ONCE(*recent);
	struct agnocast_topic *topic;

	if (ep && ep->id == id && ep->topic->handle == handle && ep->publisher == publisher) {
		*out = ep;
		return 0;
	}
	topic = agnocast_topic_by_handle(ns, handle);
	if (!topic)
		return -ENOENT;
	ep = xa_load(&topic->endpoints, id);
	if (!ep || ep->publisher != publisher)
		return -ENOENT;
	if (ep->proc != proc)
		return -EPERM;
	WRITE_ONCE(*recent, ep);
	*out = ep;
	return 0;
}

/* Teardown: every endpoint of @proc, subscribers first. */
void agnocast_proc_drop_endpoints(struct agnocast_proc *proc)
{
	struct agnocast_endpoint *ep, *tmp;
	struct agnocast_topic *topic;

	lockdep_assert_held_write(&proc->ns->lock);
	list_for_each_entry_safe(ep, tmp, &proc->subscribers, proc_node) {
		topic = ep->topic;
		agnocast_endpoint_destroy(ep);
		agnocast_topic_maybe_free(topic);
	}
	list_for_each_entry_safe(ep, tmp, &proc->publishers, proc_node) {
		topic = ep->topic;
		agnocast_endpoint_destroy(ep);
		agnocast_topic_maybe_free(topic);
	}
}
