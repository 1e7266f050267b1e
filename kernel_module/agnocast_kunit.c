// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: KUnit tests of the entry engine (agnocast_kunit.ko).
 *
 * The module compiles its own copy of the engine (agnocast_entry.c), so it
 * loads beside agnocast.ko or without it, and drives it on topics,
 * publishers, subscribers, pools and processes built here: no device, no
 * namespace lookups, no user memory.  Kbuild builds it for kernels with
 * KUnit (the VM suite's debug kernel); loading it runs the suite, whose KTAP
 * report the VM test kunit-check reads.
 */
#include <kunit/test.h>
#include <linux/module.h>
#include <linux/slab.h>

/* Its copy of the engine traces nothing: agnocast.ko owns the events. */
#ifndef AGNOCAST_UNTRACED
#define AGNOCAST_UNTRACED
#endif
#include "agnocast_entry.c"

/* The parameter the engine reads; tests set it. */
unsigned int agnocast_max_held_per_subscriber;

#define AGNOCAST_KUNIT_HELD_MAX 4096

struct agnocast_kunit_world {
	struct kunit *test;
	struct agnocast_ns *ns;
	struct agnocast_topic topic;
	struct agnocast_proc owner;	/* the publishers' process */
	struct agnocast_proc other;	/* the subscribers' process */
	struct agnocast_mempool pool;	/* owner's */
	u32 next_id;
	struct agnocast_subscriber *subs[8];
	u32 nr_subs;
};

static void agnocast_kunit_proc_init(struct agnocast_proc *proc, struct agnocast_ns *ns)
{
	proc->ns = ns;
	spin_lock_init(&proc->reclaim_lock);
	INIT_LIST_HEAD(&proc->reclaim);
	INIT_LIST_HEAD(&proc->publishers);
	INIT_LIST_HEAD(&proc->subscribers);
}

static struct agnocast_kunit_world *agnocast_kunit_world(struct kunit *test)
{
	struct agnocast_kunit_world *w = kunit_kzalloc(test, sizeof(*w), GFP_KERNEL);

	KUNIT_ASSERT_NOT_ERR_OR_NULL(test, w);
	w->test = test;
	w->ns = kunit_kzalloc(test, sizeof(*w->ns), GFP_KERNEL);
	KUNIT_ASSERT_NOT_ERR_OR_NULL(test, w->ns);
	init_rwsem(&w->ns->lock);
	w->topic.ns = w->ns;
	mutex_init(&w->topic.lock);
	INIT_LIST_HEAD(&w->topic.entries);
	INIT_LIST_HEAD(&w->topic.publishers);
	INIT_LIST_HEAD(&w->topic.subscribers);
	w->topic.next_entry_id = 1;
	agnocast_kunit_proc_init(&w->owner, w->ns);
	agnocast_kunit_proc_init(&w->other, w->ns);
	w->pool.owner = &w->owner;
	w->pool.addr = 0x40000000000ULL;
	w->pool.size = 1 << 20;
	w->owner.pool = &w->pool;
	w->next_id = 1;
	agnocast_max_held_per_subscriber = AGNOCAST_KUNIT_HELD_MAX;
	return w;
}

static struct agnocast_publisher *agnocast_kunit_pub(struct agnocast_kunit_world *w, u32 depth,
						     u32 flags)
{
	struct agnocast_publisher *pub = kunit_kzalloc(w->test, sizeof(*pub), GFP_KERNEL);

	KUNIT_ASSERT_NOT_ERR_OR_NULL(w->test, pub);
	INIT_LIST_HEAD(&pub->window);
	pub->ep.publisher = true;
	pub->ep.topic = &w->topic;
	pub->ep.proc = &w->owner;
	pub->ep.id = w->next_id++;
	pub->ep.depth = depth;
	pub->ep.flags = flags;
	list_add_tail(&pub->ep.topic_node, &w->topic.publishers);
	list_add_tail(&pub->ep.proc_node, &w->owner.publishers);
	w->topic.nr_publishers++;
	return pub;
}

/* A subscriber of @proc (the publishers' own or another). */
static struct agnocast_subscriber *agnocast_kunit_sub(struct agnocast_kunit_world *w,
						      struct agnocast_proc *proc, u32 depth,
						      u32 flags)
{
	struct agnocast_subscriber *sub = kunit_kzalloc(w->test, sizeof(*sub), GFP_KERNEL);

	KUNIT_ASSERT_NOT_ERR_OR_NULL(w->test, sub);
	KUNIT_ASSERT_LT(w->test, w->nr_subs, (u32)ARRAY_SIZE(w->subs));
	sub->unreceived = kunit_kcalloc(w->test, depth, sizeof(*sub->unreceived), GFP_KERNEL);
	KUNIT_ASSERT_NOT_ERR_OR_NULL(w->test, sub->unreceived);
	/* Like the module's: the engine may replace it (kvfree). */
	sub->held_capacity = 2 * depth;
	sub->held = kvmalloc_array(sub->held_capacity, sizeof(*sub->held), GFP_KERNEL);
	KUNIT_ASSERT_NOT_ERR_OR_NULL(w->test, sub->held);
	sub->ep.topic = &w->topic;
	sub->ep.proc = proc;
	sub->ep.id = w->next_id++;
	sub->ep.depth = depth;
	sub->ep.flags = flags;
	list_add_tail(&sub->ep.topic_node, &w->topic.subscribers);
	w->topic.nr_subscribers++;
	if (!(flags & AGNOCAST_POLLING))
		w->topic.nr_callback_subscribers++;
	w->subs[w->nr_subs++] = sub;
	return sub;
}

/* Publishes one entry at pool offset @offset; returns it, @wake filled. */
static struct agnocast_topic_entry *agnocast_kunit_publish(struct agnocast_kunit_world *w,
							   struct agnocast_publisher *pub,
							   u64 offset, u32 *wake, u32 *nr_wake)
{
	struct agnocast_topic_entry *entry = agnocast_entry_alloc();
	u32 wake_local[8], n;

	KUNIT_ASSERT_NOT_ERR_OR_NULL(w->test, entry);
	mutex_lock(&w->topic.lock);
	n = agnocast_entry_publish(pub, NULL, entry, &w->pool, w->pool.addr + offset, 64,
				   wake ? wake : wake_local);
	mutex_unlock(&w->topic.lock);
	if (nr_wake)
		*nr_wake = n;
	return entry;
}

static u32 agnocast_kunit_reclaimable(struct agnocast_kunit_world *w)
{
	u32 n;

	spin_lock(&w->owner.reclaim_lock);
	n = w->owner.nr_reclaim;
	spin_unlock(&w->owner.reclaim_lock);
	return n;
}

/* Drops every reference and frees what the engine allocated. */
static void agnocast_kunit_end(struct agnocast_kunit_world *w)
{
	struct agnocast_endpoint *ep;
	u32 i;

	mutex_lock(&w->topic.lock);
	for (i = 0; i < w->nr_subs; i++)
		agnocast_sub_drop_entries(w->subs[i]);
	list_for_each_entry(ep, &w->topic.publishers, topic_node)
		agnocast_publisher_drop_window(agnocast_to_publisher(ep));
	mutex_unlock(&w->topic.lock);
	KUNIT_EXPECT_EQ(w->test, w->topic.nr_entries, 0U);
	KUNIT_EXPECT_TRUE(w->test, list_empty(&w->topic.entries));
	KUNIT_EXPECT_EQ(w->test, atomic_long_read(&w->pool.entries), 0L);
	down_write(&w->ns->lock);
	agnocast_proc_drop_reclaim(&w->owner);
	up_write(&w->ns->lock);
	for (i = 0; i < w->nr_subs; i++)
		kvfree(w->subs[i]->held);
	mutex_destroy(&w->topic.lock);
}

/*
 * One publish computes the wake set once: callback subscribers are woken,
 * polling ones get the entry without a wake-up, and a subscriber ignoring
 * its own process gets neither.
 */
static void agnocast_kunit_wake_set(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 4, 0);
	struct agnocast_subscriber *cb = agnocast_kunit_sub(w, &w->other, 4, 0);
	struct agnocast_subscriber *poll = agnocast_kunit_sub(w, &w->other, 4, AGNOCAST_POLLING);
	struct agnocast_subscriber *own =
		agnocast_kunit_sub(w, &w->owner, 4, AGNOCAST_IGNORE_LOCAL);
	struct agnocast_subscriber *local = agnocast_kunit_sub(w, &w->owner, 4, 0);
	struct agnocast_topic_entry *entry;
	u32 wake[8], n;

	entry = agnocast_kunit_publish(w, pub, 0, wake, &n);
	KUNIT_ASSERT_EQ(test, n, 2U);
	KUNIT_EXPECT_EQ(test, wake[0], cb->ep.id);
	KUNIT_EXPECT_EQ(test, wake[1], local->ep.id);
	KUNIT_EXPECT_EQ(test, cb->nr_unreceived, 1U);
	KUNIT_EXPECT_EQ(test, poll->nr_unreceived, 1U);
	KUNIT_EXPECT_EQ(test, own->nr_unreceived, 0U);
	KUNIT_EXPECT_EQ(test, local->nr_unreceived, 1U);
	/* The window's reference and one per subscriber that has it. */
	KUNIT_EXPECT_EQ(test, entry->refs, 4U);
	KUNIT_EXPECT_EQ(test, pub->published, 1ULL);
	KUNIT_EXPECT_EQ(test, atomic_long_read(&w->pool.entries), 1L);
	agnocast_kunit_end(w);
}

/* A full subscriber drops its oldest; receiving is oldest first. */
static void agnocast_kunit_ring_order(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 8, 0);
	struct agnocast_subscriber *sub = agnocast_kunit_sub(w, &w->other, 3, 0);
	struct agnocast_entry out[3];
	u64 ids[5];
	u32 i, n;

	for (i = 0; i < 5; i++)
		ids[i] = agnocast_kunit_publish(w, pub, i * 64, NULL, NULL)->id;
	KUNIT_EXPECT_EQ(test, sub->nr_unreceived, 3U);
	KUNIT_EXPECT_EQ(test, sub->dropped, 2ULL);
	mutex_lock(&w->topic.lock);
	KUNIT_ASSERT_EQ(test, agnocast_sub_receivable(sub, 0, 8, &n), 0);
	KUNIT_ASSERT_EQ(test, n, 3U);
	KUNIT_ASSERT_EQ(test, agnocast_sub_reserve_held(sub, n), 0);
	agnocast_sub_receive(sub, out, n);
	mutex_unlock(&w->topic.lock);
	for (i = 0; i < 3; i++) {
		KUNIT_EXPECT_EQ(test, out[i].entry_id, ids[i + 2]);
		KUNIT_EXPECT_EQ(test, out[i].addr, w->pool.addr + (i + 2) * 64);
		KUNIT_EXPECT_EQ(test, out[i].publisher_id, pub->ep.id);
	}
	KUNIT_EXPECT_EQ(test, sub->nr_unreceived, 0U);
	KUNIT_EXPECT_EQ(test, sub->nr_held, 3U);
	KUNIT_EXPECT_EQ(test, sub->received, 3ULL);
	agnocast_kunit_end(w);
}

/*
 * The held quota: a RECEIVE takes no more than max_held_per_subscriber
 * allows, counting the entries it releases as released; a full quota with
 * an entry waiting is -EDQUOT, releasing more than is held -ENOENT.
 */
static void agnocast_kunit_held_quota(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 8, 0);
	struct agnocast_subscriber *sub = agnocast_kunit_sub(w, &w->other, 8, 0);
	struct agnocast_entry out[8];
	u32 i, n;

	agnocast_max_held_per_subscriber = 3;
	for (i = 0; i < 5; i++)
		agnocast_kunit_publish(w, pub, i * 64, NULL, NULL);
	mutex_lock(&w->topic.lock);
	KUNIT_ASSERT_EQ(test, agnocast_sub_receivable(sub, 0, 8, &n), 0);
	KUNIT_EXPECT_EQ(test, n, 3U);
	KUNIT_ASSERT_EQ(test, agnocast_sub_reserve_held(sub, n), 0);
	agnocast_sub_receive(sub, out, n);
	KUNIT_EXPECT_EQ(test, agnocast_sub_receivable(sub, 0, 8, &n), -EDQUOT);
	KUNIT_EXPECT_EQ(test, agnocast_sub_takeable(sub), -EDQUOT);
	KUNIT_EXPECT_EQ(test, agnocast_sub_receivable(sub, 4, 8, &n), -ENOENT);
	/* Releasing two leaves room for two of the two still waiting. */
	KUNIT_ASSERT_EQ(test, agnocast_sub_receivable(sub, 2, 8, &n), 0);
	KUNIT_EXPECT_EQ(test, n, 2U);
	/* Asked for one, one it gets. */
	KUNIT_ASSERT_EQ(test, agnocast_sub_receivable(sub, 2, 1, &n), 0);
	KUNIT_EXPECT_EQ(test, n, 1U);
	mutex_unlock(&w->topic.lock);
	agnocast_kunit_end(w);
}

/* RELEASE is all or none; released entries out of the window are reclaimable. */
static void agnocast_kunit_release(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 1, 0);
	struct agnocast_subscriber *sub = agnocast_kunit_sub(w, &w->other, 4, 0);
	struct agnocast_entry out[3];
	u64 ids[2], addrs[4];
	u32 i, n, pending;

	for (i = 0; i < 3; i++)
		agnocast_kunit_publish(w, pub, i * 64, NULL, NULL);
	mutex_lock(&w->topic.lock);
	KUNIT_ASSERT_EQ(test, agnocast_sub_receivable(sub, 0, 8, &n), 0);
	KUNIT_ASSERT_EQ(test, agnocast_sub_reserve_held(sub, n), 0);
	agnocast_sub_receive(sub, out, n);
	KUNIT_ASSERT_EQ(test, n, 3U);
	/* An id not held, or one listed twice: nothing is released. */
	ids[0] = out[0].entry_id;
	ids[1] = out[2].entry_id + 100;
	KUNIT_EXPECT_EQ(test, agnocast_sub_release(sub, ids, 2), -ENOENT);
	ids[1] = out[0].entry_id;
	KUNIT_EXPECT_EQ(test, agnocast_sub_release(sub, ids, 2), -ENOENT);
	KUNIT_EXPECT_EQ(test, sub->nr_held, 3U);
	/* The newest is still in the window: only the two older are freed. */
	ids[0] = out[2].entry_id;
	ids[1] = out[0].entry_id;
	KUNIT_EXPECT_EQ(test, agnocast_sub_release(sub, ids, 2), 0);
	KUNIT_EXPECT_EQ(test, sub->nr_held, 1U);
	KUNIT_EXPECT_EQ(test, sub->held[0]->id, out[1].entry_id);
	mutex_unlock(&w->topic.lock);
	KUNIT_EXPECT_EQ(test, agnocast_kunit_reclaimable(w), 1U);
	KUNIT_ASSERT_EQ(test, agnocast_reclaim_take(&w->owner, addrs, 4, &pending), 1U);
	KUNIT_EXPECT_EQ(test, addrs[0], out[0].addr);
	KUNIT_EXPECT_EQ(test, pending, 0U);
	agnocast_kunit_end(w);
}

/* TAKE holds the newest and passes over the older unreceived ones. */
static void agnocast_kunit_take_newest(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 1, 0);
	struct agnocast_subscriber *sub = agnocast_kunit_sub(w, &w->other, 4, AGNOCAST_POLLING);
	struct agnocast_topic_entry *newest = NULL;
	struct agnocast_entry out;
	u32 i;

	for (i = 0; i < 3; i++)
		newest = agnocast_kunit_publish(w, pub, i * 64, NULL, NULL);
	mutex_lock(&w->topic.lock);
	KUNIT_ASSERT_EQ(test, agnocast_sub_takeable(sub), 0);
	KUNIT_ASSERT_EQ(test, agnocast_sub_reserve_held(sub, 1), 0);
	agnocast_sub_take_newest(sub, &out);
	mutex_unlock(&w->topic.lock);
	KUNIT_EXPECT_EQ(test, out.entry_id, newest->id);
	KUNIT_EXPECT_EQ(test, sub->nr_unreceived, 0U);
	KUNIT_EXPECT_EQ(test, sub->nr_held, 1U);
	/* Passed over, not dropped. */
	KUNIT_EXPECT_EQ(test, sub->dropped, 0ULL);
	/* The two older left the window and the subscriber: reclaimable. */
	KUNIT_EXPECT_EQ(test, agnocast_kunit_reclaimable(w), 2U);
	agnocast_kunit_end(w);
}

/*
 * SHED takes the caller's entries that left their window and wait only to be
 * received, from every subscriber, keeping the order of the rest; held ones
 * stay.
 */
static void agnocast_kunit_shed(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 2, 0);
	struct agnocast_subscriber *a = agnocast_kunit_sub(w, &w->other, 8, 0);
	struct agnocast_subscriber *b = agnocast_kunit_sub(w, &w->other, 8, AGNOCAST_POLLING);
	struct agnocast_entry out;
	u64 ids[5];
	u32 i, n, reclaimable;

	for (i = 0; i < 5; i++)
		ids[i] = agnocast_kunit_publish(w, pub, i * 64, NULL, NULL)->id;
	/* b holds the oldest: it stays. */
	mutex_lock(&w->topic.lock);
	KUNIT_ASSERT_EQ(test, agnocast_sub_receivable(b, 0, 1, &n), 0);
	KUNIT_ASSERT_EQ(test, agnocast_sub_reserve_held(b, n), 0);
	agnocast_sub_receive(b, &out, n);
	mutex_unlock(&w->topic.lock);
	KUNIT_EXPECT_EQ(test, out.entry_id, ids[0]);

	/* Entries 0..2 left the window of 2: a sheds 3, b 2 (it holds 0). */
	KUNIT_EXPECT_EQ(test, agnocast_proc_shed(&w->owner, &reclaimable), 5U);
	KUNIT_EXPECT_EQ(test, a->nr_unreceived, 2U);
	KUNIT_EXPECT_EQ(test, b->nr_unreceived, 2U);
	KUNIT_EXPECT_EQ(test, a->dropped, 3ULL);
	KUNIT_EXPECT_EQ(test, b->dropped, 2ULL);
	KUNIT_EXPECT_EQ(test, agnocast_sub_unreceived(a, 0)->id, ids[3]);
	KUNIT_EXPECT_EQ(test, agnocast_sub_unreceived(a, 1)->id, ids[4]);
	KUNIT_EXPECT_EQ(test, agnocast_sub_unreceived(b, 0)->id, ids[3]);
	KUNIT_EXPECT_EQ(test, b->nr_held, 1U);
	/* Entries 1 and 2 are free; 0 is held by b. */
	KUNIT_EXPECT_EQ(test, reclaimable, 2U);
	/* Nothing more to shed. */
	KUNIT_EXPECT_EQ(test, agnocast_proc_shed(&w->owner, &reclaimable), 0U);
	agnocast_kunit_end(w);
}

/*
 * An entry of a pool whose owner is gone is freed at its last reference, and
 * the pool's last one asks for the pool to be collected.
 */
static void agnocast_kunit_ownerless_pool(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 1, 0);
	struct agnocast_subscriber *sub = agnocast_kunit_sub(w, &w->other, 4, 0);

	agnocast_kunit_publish(w, pub, 0, NULL, NULL);
	agnocast_kunit_publish(w, pub, 64, NULL, NULL);
	w->pool.owner = NULL;
	mutex_lock(&w->topic.lock);
	agnocast_publisher_drop_window(pub);
	KUNIT_EXPECT_EQ(test, atomic_long_read(&w->pool.entries), 2L);
	agnocast_sub_drop_entries(sub);
	mutex_unlock(&w->topic.lock);
	KUNIT_EXPECT_EQ(test, atomic_long_read(&w->pool.entries), 0L);
	KUNIT_EXPECT_TRUE(test, READ_ONCE(w->ns->collect_pools));
	KUNIT_EXPECT_EQ(test, agnocast_kunit_reclaimable(w), 0U);
	agnocast_kunit_end(w);
}

/* A transient-local subscriber starts with the newest entries still in windows. */
static void agnocast_kunit_transient(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *durable = agnocast_kunit_pub(w, 2, AGNOCAST_TRANSIENT_LOCAL);
	struct agnocast_publisher *volatile_pub = agnocast_kunit_pub(w, 4, 0);
	struct agnocast_subscriber *late;
	u64 ids[4];
	u32 i;

	for (i = 0; i < 4; i++)
		ids[i] = agnocast_kunit_publish(w, i % 2 ? volatile_pub : durable, i * 64,
						NULL, NULL)->id;
	/* durable's window of 2 holds entries 0 and 2. */
	late = agnocast_kunit_sub(w, &w->other, 4, 0);
	mutex_lock(&w->topic.lock);
	agnocast_sub_fill_transient(late);
	mutex_unlock(&w->topic.lock);
	KUNIT_ASSERT_EQ(test, late->nr_unreceived, 2U);
	KUNIT_EXPECT_EQ(test, agnocast_sub_unreceived(late, 0)->id, ids[0]);
	KUNIT_EXPECT_EQ(test, agnocast_sub_unreceived(late, 1)->id, ids[2]);
	agnocast_kunit_end(w);
}

/*
 * A wake-once subscriber is woken by the first publish after it last looked
 * and left out of the wake set until it looks again; others are woken by
 * every publish.  Looking with nothing unreceived counts too.
 */
static void agnocast_kunit_wake_once(struct kunit *test)
{
	struct agnocast_kunit_world *w = agnocast_kunit_world(test);
	struct agnocast_publisher *pub = agnocast_kunit_pub(w, 8, 0);
	struct agnocast_subscriber *once = agnocast_kunit_sub(w, &w->other, 8, AGNOCAST_WAKE_ONCE);
	struct agnocast_subscriber *every = agnocast_kunit_sub(w, &w->other, 8, 0);
	struct agnocast_entry out[8];
	u32 wake[8], i, n, sent = 0;

	for (i = 0; i < 4; i++) {
		agnocast_kunit_publish(w, pub, i * 64, wake, &n);
		sent += n;
		KUNIT_EXPECT_EQ(test, wake[n - 1], every->ep.id);
		if (!i) {
			KUNIT_EXPECT_EQ(test, n, 2U);
			KUNIT_EXPECT_EQ(test, wake[0], once->ep.id);
		} else {
			KUNIT_EXPECT_EQ(test, n, 1U);
		}
	}
	/* Four entries, five notifications: one for once, four for every. */
	KUNIT_EXPECT_EQ(test, sent, 5U);
	KUNIT_EXPECT_EQ(test, once->nr_unreceived, 4U);

	/* A RECEIVE takes all four; the next publish wakes it again. */
	mutex_lock(&w->topic.lock);
	KUNIT_ASSERT_EQ(test, agnocast_sub_receivable(once, 0, 8, &n), 0);
	KUNIT_ASSERT_EQ(test, n, 4U);
	KUNIT_ASSERT_EQ(test, agnocast_sub_reserve_held(once, n), 0);
	agnocast_sub_receive(once, out, n);
	mutex_unlock(&w->topic.lock);
	agnocast_kunit_publish(w, pub, 4 * 64, wake, &n);
	KUNIT_ASSERT_EQ(test, n, 2U);
	KUNIT_EXPECT_EQ(test, wake[0], once->ep.id);

	/* A RECEIVE that finds the quota full still looks. */
	agnocast_max_held_per_subscriber = 4;
	mutex_lock(&w->topic.lock);
	KUNIT_EXPECT_EQ(test, agnocast_sub_receivable(once, 0, 8, &n), -EDQUOT);
	mutex_unlock(&w->topic.lock);
	agnocast_kunit_publish(w, pub, 5 * 64, wake, &n);
	KUNIT_ASSERT_EQ(test, n, 2U);
	KUNIT_EXPECT_EQ(test, wake[0], once->ep.id);
	agnocast_kunit_end(w);
}

static int agnocast_kunit_suite_init(struct kunit_suite *suite)
{
	return agnocast_entry_init();
}

static void agnocast_kunit_suite_exit(struct kunit_suite *suite)
{
	agnocast_entry_exit();
}

static struct kunit_case agnocast_entry_cases[] = {
	KUNIT_CASE(agnocast_kunit_wake_set),
	KUNIT_CASE(agnocast_kunit_ring_order),
	KUNIT_CASE(agnocast_kunit_held_quota),
	KUNIT_CASE(agnocast_kunit_release),
	KUNIT_CASE(agnocast_kunit_take_newest),
	KUNIT_CASE(agnocast_kunit_shed),
	KUNIT_CASE(agnocast_kunit_ownerless_pool),
	KUNIT_CASE(agnocast_kunit_transient),
	KUNIT_CASE(agnocast_kunit_wake_once),
	{}
};

static struct kunit_suite agnocast_entry_suite = {
	.name = "agnocast_entry",
	.suite_init = agnocast_kunit_suite_init,
	.suite_exit = agnocast_kunit_suite_exit,
	.test_cases = agnocast_entry_cases,
};

kunit_test_suite(agnocast_entry_suite);

MODULE_LICENSE("GPL");
MODULE_DESCRIPTION("agnocast: KUnit tests of the entry engine");
