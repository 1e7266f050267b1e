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
 * ring drops its oldest) and its held ones in an array ordered by entry id,
 * which grows when needed and never shrinks, so receiving and releasing
 * allocate nothing in a subscriber's steady state.
 *
 * This file never touches user memory and never calls back into topics or
 * ioctls.  Everything about a topic's entries runs under the topic's lock
 * (the namespace lock held at least for read); a process's reclaim list is
 * under its reclaim_lock, since entries of any topic end up there.
 */
#include <linux/slab.h>
#include <linux/string.h>

#include "agnocast_internal.h"
#include "agnocast_trace.h"

static struct kmem_cache *agnocast_entry_cache;

int agnocast_entry_init(void)
{
	/* Named after the module: the unit tests' copy of the engine has its own. */
	agnocast_entry_cache = kmem_cache_create(KBUILD_MODNAME "_entry",
						 sizeof(struct agnocast_topic_entry),
						 __alignof__(struct agnocast_topic_entry),
						 SLAB_ACCOUNT, NULL);
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
	trace_reclaim(entry);
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
		struct agnocast_topic_entry *oldest = agnocast_sub_pop_oldest(sub);

		trace_drop(sub, oldest, AGNOCAST_DROP_DEPTH);
		agnocast_entry_unref(oldest);
		sub->dropped++;
	}
	sub->unreceived[(sub->head + sub->nr_unreceived) % sub->ep.depth] = entry;
	sub->nr_unreceived++;
	entry->refs++;
}

/*
 * Whether @sub is woken for a new entry of @pub: a callback subscriber is,
 * through its notification queue, but one with AGNOCAST_WAKE_ONCE only if it
 * was not woken since it last looked (RECEIVE or TAKE); a polling one never
 * is.  A listing is a promise (agnocast_wake_promise()).
 */
static bool agnocast_sub_wake(struct agnocast_subscriber *sub, struct agnocast_publisher *pub)
{
	if (sub->ep.flags & AGNOCAST_POLLING)
		return false;
	if ((sub->ep.flags & AGNOCAST_WAKE_ONCE) && sub->notified)
		return false;
	agnocast_wake_promise(sub, pub->ep.proc);
	return true;
}

/*
 * @sub looks at what is unreceived (RECEIVE or TAKE, whatever they return):
 * the next entry published wakes it again.
 */
static void agnocast_sub_looks(struct agnocast_subscriber *sub)
{
	WRITE_ONCE(sub->notified, false);
}

/*
 * Whether an entry of @pub may be published without dropping anything
 * (AGNOCAST_PUBLISH_NO_DROP): 0, -EAGAIN when a subscriber that would get it
 * is full, -EPIPE when none would get it.  @to: the one receiver, or NULL
 * for every subscriber that does not ignore @pub's process.
 */
int agnocast_entry_admits(struct agnocast_publisher *pub, struct agnocast_subscriber *to)
{
	struct agnocast_endpoint *ep;
	bool any = false;

	lockdep_assert_held(&pub->ep.topic->lock);
	if (to)
		return to->nr_unreceived == to->ep.depth ? -EAGAIN : 0;
	list_for_each_entry(ep, &pub->ep.topic->subscribers, topic_node) {
		if (agnocast_sub_ignores(ep, pub))
			continue;
		if (agnocast_to_subscriber(ep)->nr_unreceived == ep->depth)
			return -EAGAIN;
		any = true;
	}
	return any ? 0 : -EPIPE;
}

/*
 * Makes @entry (allocated, zeroed) the newest of @pub's topic: @to alone, or
 * without @to every subscriber but those ignoring @pub's process, gets it
 * unreceived, and the ids of those to wake are written to @wake, which has
 * room for them.  Returns how many were written.
 */
u32 agnocast_entry_publish(struct agnocast_publisher *pub, struct agnocast_subscriber *to,
			   struct agnocast_topic_entry *entry, struct agnocast_mempool *pool,
			   u64 addr, u64 bytes, u32 *wake)
{
	struct agnocast_topic *topic = pub->ep.topic;
	struct agnocast_subscriber *sub;
	struct agnocast_endpoint *ep;
	u32 nr_wake = 0;

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
	if (to) {
		agnocast_sub_push(to, entry);
		if (agnocast_sub_wake(to, pub))
			wake[nr_wake++] = to->ep.id;
	} else {
		list_for_each_entry(ep, &topic->subscribers, topic_node) {
			if (agnocast_sub_ignores(ep, pub))
				continue;
			sub = agnocast_to_subscriber(ep);
			agnocast_sub_push(sub, entry);
			if (!agnocast_sub_wake(sub, pub))
				continue;
			if (!WARN_ON_ONCE(nr_wake == topic->nr_callback_subscribers))
				wake[nr_wake++] = ep->id;
		}
	}
	if (pub->window_len > pub->ep.depth)
		agnocast_entry_leave_window(list_first_entry(&pub->window,
							     struct agnocast_topic_entry,
							     window_node));
	trace_publish(pub, entry, bytes, nr_wake);
	return nr_wake;
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

/* Drops every unreceived and held reference of @sub, which goes. */
void agnocast_sub_drop_entries(struct agnocast_subscriber *sub)
{
	struct agnocast_topic_entry *entry;
	u32 i;

	while (sub->nr_unreceived) {
		entry = agnocast_sub_pop_oldest(sub);
		trace_drop(sub, entry, AGNOCAST_DROP_REMOVED);
		agnocast_entry_unref(entry);
	}
	for (i = 0; i < sub->nr_held; i++) {
		trace_release(sub, sub->held[i]);
		agnocast_entry_unref(sub->held[i]);
	}
	sub->nr_held = 0;
}

/*
 * Makes room for @n more held entries, so that holding them cannot fail.
 * The array only grows (it starts at twice the depth), so a subscriber in
 * its steady state allocates nothing here.
 */
int agnocast_sub_reserve_held(struct agnocast_subscriber *sub, u32 n)
{
	struct agnocast_topic_entry **held;
	u32 capacity;

	lockdep_assert_held(&sub->ep.topic->lock);
	if (n <= sub->held_capacity - sub->nr_held)
		return 0;
	capacity = max(sub->nr_held + n, 2 * sub->held_capacity);
	held = kvmalloc_array(capacity, sizeof(*held), GFP_KERNEL_ACCOUNT);
	if (!held)
		return -ENOMEM;
	memcpy(held, sub->held, sub->nr_held * sizeof(*held));
	kvfree(sub->held);
	sub->held = held;
	sub->held_capacity = capacity;
	return 0;
}

/*
 * Stores into reserved room.  Entries are held in the order of their ids:
 * a subscriber receives its entries oldest first, and TAKE passes over the
 * older ones, so the newest held is always the one just taken.
 */
static void agnocast_sub_hold(struct agnocast_subscriber *sub,
			      struct agnocast_topic_entry *entry)
{
	WARN_ON_ONCE(sub->nr_held && sub->held[sub->nr_held - 1]->id >= entry->id);
	sub->held[sub->nr_held++] = entry;
	sub->received++;
}

static void agnocast_entry_out(struct agnocast_entry *out,
			       const struct agnocast_topic_entry *entry)
{
	memset(out, 0, sizeof(*out));
	out->entry_id = entry->id;
	out->addr = entry->addr;
	out->publisher_id = entry->publisher_id;
}

/*
 * How many of @sub's unreceived entries a RECEIVE of at most @max that
 * releases @release_count held ones may take, within
 * max_held_per_subscriber (held entries about to be released count as
 * released already): -ENOENT when fewer are held than are to be released,
 * -EDQUOT when the quota is full and an entry waits.  The subscriber looks,
 * whatever the answer.
 */
int agnocast_sub_receivable(struct agnocast_subscriber *sub, u32 release_count, u32 max, u32 *n)
{
	u32 held_after;

	agnocast_sub_looks(sub);
	if (release_count > sub->nr_held)
		return -ENOENT;
	held_after = sub->nr_held - release_count;
	*n = min(max, sub->nr_unreceived);
	if (held_after >= agnocast_max_held_per_subscriber)
		return *n ? -EDQUOT : 0;
	*n = min(*n, agnocast_max_held_per_subscriber - held_after);
	return 0;
}

/*
 * Whether TAKE may hold one more entry of @sub: -EDQUOT when its quota is
 * full.  The subscriber looks, whatever the answer.
 */
int agnocast_sub_takeable(struct agnocast_subscriber *sub)
{
	agnocast_sub_looks(sub);
	return sub->nr_held >= agnocast_max_held_per_subscriber ? -EDQUOT : 0;
}

/*
 * RECEIVE: the @n oldest unreceived entries (room reserved) become held,
 * described in @out, oldest first.
 */
void agnocast_sub_receive(struct agnocast_subscriber *sub, struct agnocast_entry *out, u32 n)
{
	u32 i;

	lockdep_assert_held(&sub->ep.topic->lock);
	for (i = 0; i < n; i++) {
		agnocast_entry_out(&out[i], sub->unreceived[sub->head]);
		trace_receive(sub, sub->unreceived[sub->head], n);
		agnocast_sub_hold(sub, agnocast_sub_pop_oldest(sub));
	}
}

/*
 * TAKE: the newest unreceived entry (room reserved) becomes held, described
 * in @out; older unreceived entries are passed over, not dropped.
 */
void agnocast_sub_take_newest(struct agnocast_subscriber *sub, struct agnocast_entry *out)
{
	struct agnocast_topic_entry *entry;

	lockdep_assert_held(&sub->ep.topic->lock);
	while (sub->nr_unreceived > 1) {
		entry = agnocast_sub_pop_oldest(sub);
		trace_drop(sub, entry, AGNOCAST_DROP_PASSED_OVER);
		agnocast_entry_unref(entry);
	}
	agnocast_entry_out(out, sub->unreceived[sub->head]);
	trace_receive(sub, sub->unreceived[sub->head], 1);
	agnocast_sub_hold(sub, agnocast_sub_pop_oldest(sub));
}

/* While a release is checked, bit 0 of a held pointer flags it listed. */
#define AGNOCAST_HELD_LISTED 1UL

static bool agnocast_held_listed(const struct agnocast_topic_entry *entry)
{
	return (unsigned long)entry & AGNOCAST_HELD_LISTED;
}

static struct agnocast_topic_entry *agnocast_held_flip(struct agnocast_topic_entry *entry)
{
	return (struct agnocast_topic_entry *)((unsigned long)entry ^ AGNOCAST_HELD_LISTED);
}

/* The index of held entry @id (binary search, listed or not), or -1. */
static int agnocast_sub_find_held(const struct agnocast_subscriber *sub, u64 id)
{
	u32 lo = 0, hi = sub->nr_held;

	while (lo < hi) {
		u32 mid = lo + (hi - lo) / 2;
		const struct agnocast_topic_entry *entry = sub->held[mid];
		u64 mid_id;

		if (agnocast_held_listed(entry))
			entry = agnocast_held_flip((struct agnocast_topic_entry *)entry);
		mid_id = entry->id;
		if (mid_id == id)
			return mid;
		if (mid_id < id)
			lo = mid + 1;
		else
			hi = mid;
	}
	return -1;
}

/*
 * Drops @sub's references to the @n entries @ids, all or none (-ENOENT when
 * one is not held, or listed twice).  Held entries are found by binary
 * search; the array is then compacted from the first one released.
 */
int agnocast_sub_release(struct agnocast_subscriber *sub, const u64 *ids, u32 n)
{
	u32 i, r, w, first = U32_MAX;
	int k;

	lockdep_assert_held(&sub->ep.topic->lock);
	for (i = 0; i < n; i++) {
		k = agnocast_sub_find_held(sub, ids[i]);
		if (k < 0 || agnocast_held_listed(sub->held[k]))
			break;
		sub->held[k] = agnocast_held_flip(sub->held[k]);
		first = min_t(u32, first, k);
	}
	if (i < n) {
		while (i--) {
			k = agnocast_sub_find_held(sub, ids[i]);
			sub->held[k] = agnocast_held_flip(sub->held[k]);
		}
		return -ENOENT;
	}
	if (!n)
		return 0;
	for (r = w = first; r < sub->nr_held; r++) {
		if (agnocast_held_listed(sub->held[r])) {
			struct agnocast_topic_entry *entry = agnocast_held_flip(sub->held[r]);

			trace_release(sub, entry);
			agnocast_entry_unref(entry);
			continue;
		}
		sub->held[w++] = sub->held[r];
	}
	sub->nr_held = w;
	return 0;
}

/*
 * Takes from @sub's unreceived entries those of @pool that have left their
 * publisher's window; keeps the order of the rest.
 */
static u32 agnocast_sub_shed(struct agnocast_subscriber *sub, struct agnocast_mempool *pool)
{
	u32 i, kept = 0, shed = 0, n = sub->nr_unreceived;

	for (i = 0; i < n; i++) {
		struct agnocast_topic_entry *entry = agnocast_sub_unreceived(sub, i);

		if (entry->pool == pool && !entry->publisher) {
			trace_shed(sub, entry);
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
 * SHED: takes from the subscribers of every topic @proc publishes the
 * entries of its pool that wait only to be received (counted in their
 * @dropped); held entries stay.  Takes each topic's lock in turn.  Returns
 * how many were taken; @reclaimable is then the length of @proc's reclaim
 * list.
 */
u32 agnocast_proc_shed(struct agnocast_proc *proc, u32 *reclaimable)
{
	struct agnocast_endpoint *pub, *sub;
	u32 shed = 0;

	list_for_each_entry(pub, &proc->publishers, proc_node) {
		mutex_lock(&pub->topic->lock);
		list_for_each_entry(sub, &pub->topic->subscribers, topic_node)
			shed += agnocast_sub_shed(agnocast_to_subscriber(sub), proc->pool);
		mutex_unlock(&pub->topic->lock);
	}
	spin_lock(&proc->reclaim_lock);
	*reclaimable = proc->nr_reclaim;
	spin_unlock(&proc->reclaim_lock);
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
	list_for_each_entry_safe(entry, tmp, &taken, node) {
		/* One is kept for the next PUBLISH: its allocation is the dearest step. */
		if (cmpxchg(&proc->spare_entry, NULL, entry))
			agnocast_entry_free(entry);
	}
	return n;
}

/* A zeroed entry for @proc's PUBLISH: its spare if it has one. */
struct agnocast_topic_entry *agnocast_proc_entry_alloc(struct agnocast_proc *proc)
{
	struct agnocast_topic_entry *entry = xchg(&proc->spare_entry, NULL);

	if (!entry)
		return agnocast_entry_alloc();
	memset(entry, 0, sizeof(*entry));
	return entry;
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
	if (proc->spare_entry)
		agnocast_entry_free(proc->spare_entry);
	proc->spare_entry = NULL;
}
