// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: the entry engine.
 *
 * An entry is referenced once while in its publisher's window of depth
 * newest entries and once per subscriber that has it unreceived or held.  At
 * zero it leaves the topic and, if the pool's owner still lives, waits on the
 * owner's reclaim list until PUBLISH or RECLAIM hands its address back for
 * reuse; otherwise it is freed and may free its pool.
 *
 * A subscriber keeps its unreceived entries in a ring of its depth (a full
 * ring drops its oldest) and its held ones in an xarray by entry id.
 *
 * This file never touches user memory and never calls back into topics or
 * ioctls.  Everything about a topic's entries runs under the topic's lock
 * (the namespace lock held at least for read); a process's reclaim list is
 * under its reclaim_lock, since entries of any topic end up there.
 */
#include <linux/slab.h>
#include <linux/string.h>

#include "agnocast_internal.h"

static struct kmem_cache *agnocast_entry_cache;

int agnocast_entry_init(void)
{
	agnocast_entry_cache = KMEM_CACHE(agnocast_topic_entry, SLAB_ACCOUNT);
	return agnocast_entry_cache ? 0 : -ENOMEM;
}

void agnocast_entry_exit(void)
{
	kmem_cache_destroy(agnocast_entry_cache);
}

struct agnocast_topic_entry *agnocast_entry_alloc(void)
{
	return kmem_cache_zalloc(agnocast_entry_cache, GFP_KERNEL_ACCOUNT);
}

void agnocast_entry_free(struct agnocast_topic_entry *entry)
{
	kmem_cache_free(agnocast_entry_cache, entry);
}

static void agnocast_entry_unref(struct agnocast_topic_entry *entry)
{
	struct agnocast_mempool *pool = entry->pool;
	struct agnocast_proc *owner = pool->owner;
	struct agnocast_topic *topic = entry->topic;

	lockdep_assert_held(&topic->lock);
	if (WARN_ON_ONCE(!entry->refs) || --entry->refs)
		return;
	list_del(&entry->node);
	topic->nr_entries--;
	if (owner) {
		atomic_long_dec(&pool->entries);
		spin_lock(&owner->reclaim_lock);
		list_add_tail(&entry->node, &owner->reclaim);
		owner->nr_reclaim++;
		spin_unlock(&owner->reclaim_lock);
		return;
	}
	agnocast_entry_free(entry);
	/* An ownerless pool may be free now; agnocast_leave() collects it. */
	if (atomic_long_dec_and_test(&pool->entries))
		WRITE_ONCE(topic->ns->collect_pools, true);
}

static void agnocast_entry_leave_window(struct agnocast_topic_entry *entry)
{
	struct agnocast_publisher *pub = entry->publisher;

	list_del(&entry->window_node);
	pub->window_len--;
	entry->publisher = NULL;
	agnocast_entry_unref(entry);
}

void agnocast_publisher_drop_window(struct agnocast_publisher *pub)
{
	while (!list_empty(&pub->window))
		agnocast_entry_leave_window(list_first_entry(&pub->window,
							     struct agnocast_topic_entry,
							     window_node));
}

static struct agnocast_topic_entry *agnocast_sub_pop_oldest(struct agnocast_subscriber *sub)
{
	struct agnocast_topic_entry *entry = sub->unreceived[sub->head];

	sub->head = (sub->head + 1) % sub->ep.depth;
	sub->nr_unreceived--;
	return entry;
}

struct agnocast_topic_entry *agnocast_sub_unreceived(const struct agnocast_subscriber *sub,
						     u32 i)
{
	return sub->unreceived[(sub->head + i) % sub->ep.depth];
}

/* Adds an unreceived reference; a full subscriber drops its oldest. */
static void agnocast_sub_push(struct agnocast_subscriber *sub,
			      struct agnocast_topic_entry *entry)
{
	if (sub->nr_unreceived == sub->ep.depth) {
		agnocast_entry_unref(agnocast_sub_pop_oldest(sub));
		sub->dropped++;
	}
	sub->unreceived[(sub->head + sub->nr_unreceived) % sub->ep.depth] = entry;
	sub->nr_unreceived++;
	entry->refs++;
}

/* Makes @entry (allocated, zeroed) the newest of @pub's topic. */
void agnocast_entry_publish(struct agnocast_publisher *pub, struct agnocast_topic_entry *entry,
			    struct agnocast_mempool *pool, u64 addr, u64 bytes)
{
	struct agnocast_topic *topic = pub->ep.topic;
	struct agnocast_endpoint *ep;

	lockdep_assert_held(&topic->lock);
	entry->topic = topic;
	entry->publisher = pub;
	entry->pool = pool;
	entry->id = topic->next_entry_id++;
	entry->addr = addr;
	entry->publisher_id = pub->ep.id;
	entry->refs = 1;
	list_add_tail(&entry->node, &topic->entries);
	topic->nr_entries++;
	atomic_long_inc(&pool->entries);
	list_add_tail(&entry->window_node, &pub->window);
	pub->window_len++;
	pub->published++;
	pub->published_bytes += bytes;
	list_for_each_entry(ep, &topic->subscribers, topic_node)
		if (!agnocast_sub_ignores(ep, pub))
			agnocast_sub_push(agnocast_to_subscriber(ep), entry);
	if (pub->window_len > pub->ep.depth)
		agnocast_entry_leave_window(list_first_entry(&pub->window,
							     struct agnocast_topic_entry,
							     window_node));
}

/* @entry is transient-local history @sub gets. */
static bool agnocast_entry_transient(const struct agnocast_topic_entry *entry,
				     const struct agnocast_subscriber *sub)
{
	return entry->publisher && (entry->publisher->ep.flags & AGNOCAST_TRANSIENT_LOCAL) &&
	       !agnocast_sub_ignores(&sub->ep, entry->publisher);
}

/* Transient local: the newest entries still in transient-local windows. */
void agnocast_sub_fill_transient(struct agnocast_subscriber *sub)
{
	struct agnocast_topic *topic = sub->ep.topic;
	struct agnocast_topic_entry *entry;
	u32 n = 0, i;

	list_for_each_entry_reverse(entry, &topic->entries, node) {
		if (n == sub->ep.depth)
			break;
		if (agnocast_entry_transient(entry, sub))
			n++;
	}
	i = n;
	list_for_each_entry_reverse(entry, &topic->entries, node) {
		if (!i)
			break;
		if (agnocast_entry_transient(entry, sub)) {
			sub->unreceived[--i] = entry;
			entry->refs++;
		}
	}
	sub->head = 0;
	sub->nr_unreceived = n;
}

/* Drops every unreceived and held reference of @sub. */
void agnocast_sub_drop_entries(struct agnocast_subscriber *sub)
{
	struct agnocast_topic_entry *entry;
	unsigned long id;

	while (sub->nr_unreceived)
		agnocast_entry_unref(agnocast_sub_pop_oldest(sub));
	xa_for_each(&sub->held, id, entry)
		agnocast_entry_unref(entry);
	xa_destroy(&sub->held);
	sub->nr_held = 0;
}

/*
 * Reserves the held slots of the @n oldest unreceived entries (RECEIVE) or,
 * with @newest, of the newest one (TAKE, @n 1), so that holding them cannot
 * fail.
 */
int agnocast_sub_reserve_held(struct agnocast_subscriber *sub, u32 n, bool newest)
{
	u32 first = newest ? sub->nr_unreceived - n : 0;
	u32 i;
	int ret;

	lockdep_assert_held(&sub->ep.topic->lock);
	for (i = 0; i < n; i++) {
		ret = xa_reserve(&sub->held, agnocast_sub_unreceived(sub, first + i)->id,
				 GFP_KERNEL_ACCOUNT);
		if (ret) {
			while (i--)
				xa_release(&sub->held, agnocast_sub_unreceived(sub, first + i)->id);
			return ret;
		}
	}
	return 0;
}

/* Undoes agnocast_sub_reserve_held(). */
void agnocast_sub_unreserve_held(struct agnocast_subscriber *sub, u32 n, bool newest)
{
	u32 first = newest ? sub->nr_unreceived - n : 0;
	u32 i;

	for (i = 0; i < n; i++)
		xa_release(&sub->held, agnocast_sub_unreceived(sub, first + i)->id);
}

/* Stores into a reserved slot: no allocation, cannot fail. */
static void agnocast_sub_hold(struct agnocast_subscriber *sub,
			      struct agnocast_topic_entry *entry)
{
	xa_store(&sub->held, entry->id, entry, GFP_NOWAIT);
	sub->nr_held++;
	sub->received++;
}

/* RECEIVE: the oldest unreceived entry becomes held (its slot reserved). */
void agnocast_sub_hold_oldest(struct agnocast_subscriber *sub)
{
	agnocast_sub_hold(sub, agnocast_sub_pop_oldest(sub));
}

/* TAKE: the newest becomes held; older unreceived entries are passed over. */
void agnocast_sub_take_newest(struct agnocast_subscriber *sub)
{
	while (sub->nr_unreceived > 1)
		agnocast_entry_unref(agnocast_sub_pop_oldest(sub));
	agnocast_sub_hold_oldest(sub);
}

/*
 * Drops @sub's references to the @n entries @ids, all or none (-ENOENT when
 * one is not held, or listed twice).  Held entries are found by id in an
 * xarray; a mark flags those already listed.
 */
int agnocast_sub_release(struct agnocast_subscriber *sub, const u64 *ids, u32 n)
{
	struct agnocast_topic_entry *entry;
	u32 i;

	lockdep_assert_held(&sub->ep.topic->lock);
	for (i = 0; i < n; i++) {
		if (!xa_load(&sub->held, ids[i]) || xa_get_mark(&sub->held, ids[i], XA_MARK_0))
			break;
		xa_set_mark(&sub->held, ids[i], XA_MARK_0);
	}
	if (i < n) {
		while (i--)
			xa_clear_mark(&sub->held, ids[i], XA_MARK_0);
		return -ENOENT;
	}
	for (i = 0; i < n; i++) {
		entry = xa_erase(&sub->held, ids[i]);
		sub->nr_held--;
		agnocast_entry_unref(entry);
	}
	return 0;
}

/*
 * Takes from @sub's unreceived entries those of @pool that have left their
 * publisher's window; keeps the order of the rest.
 */
u32 agnocast_sub_shed(struct agnocast_subscriber *sub, struct agnocast_mempool *pool)
{
	u32 i, kept = 0, shed = 0, n = sub->nr_unreceived;

	for (i = 0; i < n; i++) {
		struct agnocast_topic_entry *entry = agnocast_sub_unreceived(sub, i);

		if (entry->pool == pool && !entry->publisher) {
			agnocast_entry_unref(entry);
			shed++;
			continue;
		}
		/* kept <= i: this slot was read already. */
		sub->unreceived[(sub->head + kept) % sub->ep.depth] = entry;
		kept++;
	}
	sub->nr_unreceived = kept;
	sub->dropped += shed;
	return shed;
}

/*
 * Takes up to @max reclaimable addresses, oldest first, into @addrs for
 * delivery to the owner; @pending is how many are left.
 */
u32 agnocast_reclaim_take(struct agnocast_proc *proc, u64 *addrs, u32 max, u32 *pending)
{
	struct agnocast_topic_entry *entry, *tmp;
	LIST_HEAD(taken);
	u32 n = 0;

	spin_lock(&proc->reclaim_lock);
	list_for_each_entry_safe(entry, tmp, &proc->reclaim, node) {
		if (n == max)
			break;
		addrs[n++] = entry->addr;
		list_move_tail(&entry->node, &taken);
	}
	proc->nr_reclaim -= n;
	*pending = proc->nr_reclaim;
	spin_unlock(&proc->reclaim_lock);
	list_for_each_entry_safe(entry, tmp, &taken, node)
		agnocast_entry_free(entry);
	return n;
}

/*
 * Puts back addresses taken by a call that could not deliver them, as the
 * oldest reclaimable ones.  Only the address matters on the reclaim list;
 * an address is lost only if no memory is left to remember it.
 */
void agnocast_reclaim_return(struct agnocast_proc *proc, const u64 *addrs, u32 n)
{
	struct agnocast_topic_entry *entry;
	LIST_HEAD(back);
	u32 i, kept = 0;

	for (i = 0; i < n; i++) {
		entry = agnocast_entry_alloc();
		if (!entry)
			continue;
		entry->addr = addrs[i];
		list_add_tail(&entry->node, &back);
		kept++;
	}
	spin_lock(&proc->reclaim_lock);
	list_splice(&back, &proc->reclaim);
	proc->nr_reclaim += kept;
	spin_unlock(&proc->reclaim_lock);
}

/* Teardown (namespace lock held for write): frees the reclaim list. */
void agnocast_proc_drop_reclaim(struct agnocast_proc *proc)
{
	struct agnocast_topic_entry *entry, *tmp;

	lockdep_assert_held_write(&proc->ns->lock);
	list_for_each_entry_safe(entry, tmp, &proc->reclaim, node)
		agnocast_entry_free(entry);
	INIT_LIST_HEAD(&proc->reclaim);
	proc->nr_reclaim = 0;
}
