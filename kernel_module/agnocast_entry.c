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
 * ring drops its oldest) and its held ones in receive order, so that the
 * usual release, of the oldest held entry, finds it first.
 *
 * This file never touches user memory and never calls back into topics or
 * ioctls; every function runs under the namespace lock (agnocast_ns.lock).
 */
#include <linux/slab.h>
#include <linux/string.h>

#include "agnocast_internal.h"

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

struct agnocast_topic_entry *agnocast_entry_alloc(struct agnocast_proc *proc)
{
	struct agnocast_topic_entry *entry;

	lockdep_assert_held(&proc->ns->lock);
	if (list_empty(&proc->spare_entries))
		return kzalloc(sizeof(*entry), GFP_KERNEL_ACCOUNT);
	entry = list_first_entry(&proc->spare_entries, struct agnocast_topic_entry, node);
	list_del(&entry->node);
	proc->nr_spare_entries--;
	memset(entry, 0, sizeof(*entry));
	return entry;
}

void agnocast_entry_free(struct agnocast_proc *proc, struct agnocast_topic_entry *entry)
{
	lockdep_assert_held(&proc->ns->lock);
	if (!agnocast_spare_keep(&entry->node, &proc->spare_entries, &proc->nr_spare_entries))
		kfree(entry);
}

static void agnocast_entry_unref(struct agnocast_topic_entry *entry)
{
	struct agnocast_mempool *pool = entry->pool;
	struct agnocast_proc *owner = pool->owner;
	struct agnocast_topic *topic = entry->topic;

	lockdep_assert_held(&topic->ns->lock);
	if (WARN_ON_ONCE(!entry->refs) || --entry->refs)
		return;
	list_del(&entry->node);
	topic->nr_entries--;
	pool->entries--;
	if (owner) {
		list_add_tail(&entry->node, &owner->reclaim);
		owner->nr_reclaim++;
	} else {
		kfree(entry);
		agnocast_pool_maybe_free(topic->ns, pool);
	}
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

	lockdep_assert_held(&topic->ns->lock);
	entry->topic = topic;
	entry->publisher = pub;
	entry->pool = pool;
	entry->id = topic->next_entry_id++;
	entry->addr = addr;
	entry->publisher_id = pub->ep.id;
	entry->refs = 1;
	list_add_tail(&entry->node, &topic->entries);
	topic->nr_entries++;
	pool->entries++;
	list_add_tail(&entry->window_node, &pub->window);
	pub->window_len++;
	pub->published++;
	pub->published_bytes += bytes;
	list_for_each_entry(ep, &topic->subscribers, topic_node)
		agnocast_sub_push(agnocast_to_subscriber(ep), entry);
	if (pub->window_len > pub->ep.depth)
		agnocast_entry_leave_window(list_first_entry(&pub->window,
							     struct agnocast_topic_entry,
							     window_node));
}

static bool agnocast_entry_transient(const struct agnocast_topic_entry *entry)
{
	return entry->publisher && (entry->publisher->ep.flags & AGNOCAST_TRANSIENT_LOCAL);
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
		if (agnocast_entry_transient(entry))
			n++;
	}
	i = n;
	list_for_each_entry_reverse(entry, &topic->entries, node) {
		if (!i)
			break;
		if (agnocast_entry_transient(entry)) {
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
	struct agnocast_held *held, *tmp;

	while (sub->nr_unreceived)
		agnocast_entry_unref(agnocast_sub_pop_oldest(sub));
	list_for_each_entry_safe(held, tmp, &sub->held, node) {
		agnocast_entry_unref(held->entry);
		kfree(held);
	}
	INIT_LIST_HEAD(&sub->held);
	sub->nr_held = 0;
}

static void agnocast_held_free(struct agnocast_proc *proc, struct agnocast_held *held)
{
	if (!agnocast_spare_keep(&held->node, &proc->spare_held, &proc->nr_spare_held))
		kfree(held);
}

void agnocast_held_free_list(struct agnocast_proc *proc, struct list_head *list)
{
	struct agnocast_held *held, *tmp;

	lockdep_assert_held(&proc->ns->lock);
	list_for_each_entry_safe(held, tmp, list, node) {
		list_del(&held->node);
		agnocast_held_free(proc, held);
	}
}

/* Fills @list with @n held records, spares first, so that holding cannot fail. */
int agnocast_held_alloc_list(struct agnocast_proc *proc, struct list_head *list, u32 n)
{
	struct agnocast_held *held;

	lockdep_assert_held(&proc->ns->lock);
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
			      struct agnocast_topic_entry *entry)
{
	struct agnocast_held *held = list_first_entry(spare, struct agnocast_held, node);

	held->entry = entry;
	list_move_tail(&held->node, &sub->held);
	sub->nr_held++;
	sub->received++;
}

/* RECEIVE: the oldest unreceived entry becomes held (a record from @spare). */
void agnocast_sub_hold_oldest(struct agnocast_subscriber *sub, struct list_head *spare)
{
	agnocast_sub_hold(sub, spare, agnocast_sub_pop_oldest(sub));
}

/* TAKE: the newest becomes held; older unreceived entries are passed over. */
void agnocast_sub_take_newest(struct agnocast_subscriber *sub, struct list_head *spare)
{
	while (sub->nr_unreceived > 1)
		agnocast_entry_unref(agnocast_sub_pop_oldest(sub));
	agnocast_sub_hold_oldest(sub, spare);
}

/* Held entries are in receive order: the usual release finds the first. */
struct agnocast_held *agnocast_sub_find_held(struct agnocast_subscriber *sub, u64 entry_id)
{
	struct agnocast_held *held;

	list_for_each_entry(held, &sub->held, node) {
		if (held->entry->id == entry_id)
			return held;
	}
	return NULL;
}

void agnocast_sub_release(struct agnocast_subscriber *sub, struct agnocast_held *held)
{
	list_del(&held->node);
	sub->nr_held--;
	agnocast_entry_unref(held->entry);
	agnocast_held_free(sub->ep.proc, held);
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

/* Copies up to @max reclaimable addresses, oldest first, to @addrs. */
u32 agnocast_reclaim_peek(struct agnocast_proc *proc, u64 *addrs, u32 max)
{
	struct agnocast_topic_entry *entry;
	u32 n = 0;

	lockdep_assert_held(&proc->ns->lock);
	list_for_each_entry(entry, &proc->reclaim, node) {
		if (n == max)
			break;
		addrs[n++] = entry->addr;
	}
	return n;
}

/* Forgets the @n oldest reclaimable entries, delivered to the owner. */
void agnocast_reclaim_forget(struct agnocast_proc *proc, u32 n)
{
	struct agnocast_topic_entry *entry, *tmp;

	lockdep_assert_held(&proc->ns->lock);
	list_for_each_entry_safe(entry, tmp, &proc->reclaim, node) {
		if (!n--)
			break;
		list_del(&entry->node);
		proc->nr_reclaim--;
		agnocast_entry_free(proc, entry);
	}
}

/*
 * Puts back addresses forgotten by a call that could not deliver them, as
 * the oldest reclaimable ones.  Only the address matters on the reclaim
 * list; an address is lost only if no memory is left to remember it.
 */
void agnocast_reclaim_return(struct agnocast_proc *proc, const u64 *addrs, u32 n)
{
	struct agnocast_topic_entry *entry;

	lockdep_assert_held(&proc->ns->lock);
	while (n--) {
		entry = agnocast_entry_alloc(proc);
		if (!entry)
			continue;
		entry->addr = addrs[n];
		list_add(&entry->node, &proc->reclaim);
		proc->nr_reclaim++;
	}
}

/* Teardown: frees the reclaim list and the spares. */
void agnocast_proc_drop_reclaim(struct agnocast_proc *proc)
{
	struct agnocast_topic_entry *entry, *tmp;
	struct agnocast_held *held, *htmp;

	lockdep_assert_held(&proc->ns->lock);
	list_for_each_entry_safe(entry, tmp, &proc->reclaim, node)
		kfree(entry);
	INIT_LIST_HEAD(&proc->reclaim);
	proc->nr_reclaim = 0;
	list_for_each_entry_safe(entry, tmp, &proc->spare_entries, node)
		kfree(entry);
	INIT_LIST_HEAD(&proc->spare_entries);
	proc->nr_spare_entries = 0;
	list_for_each_entry_safe(held, htmp, &proc->spare_held, node)
		kfree(held);
	INIT_LIST_HEAD(&proc->spare_held);
	proc->nr_spare_held = 0;
}
