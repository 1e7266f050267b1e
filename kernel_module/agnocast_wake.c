// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: what keeps a callback subscriber from sleeping on entries.
 *
 * A PUBLISH lists a callback subscriber in its wake set (a wake-once one
 * only until it next looks); the publisher's process sends the notification
 * afterwards.  The listing is a promise (agnocast_wake_promise()), and a
 * promise the module cannot see kept is broken: the subscriber is listed
 * again by the next PUBLISH and its process's wake eventfd is signalled, on
 * which the library makes each of its callback subscribers RECEIVE.  A
 * promise breaks
 *   - when the publisher's process dies before the subscriber looked: it
 *     may have died before sending;
 *   - when the publisher reports it could not send (NOTIFY_FAILED);
 * The watchdog catches what nobody reports (a stopped publisher, a
 * notification sent into a queue that replaced the subscriber's under its
 * name): when the subscriber has not looked AGNOCAST_WAKE_WATCHDOG_MS after
 * the listing, its process's wake eventfd is signalled, once per listing.
 * It does not list the subscriber again: a subscriber that is merely slow,
 * or stopped, keeps one notification pending, not one per PUBLISH.
 * A broken promise that was kept after all costs one RECEIVE that finds
 * nothing.
 */
#include <linux/eventfd.h>
#include <linux/timer.h>
#include <linux/version.h>

#include "agnocast_internal.h"

static void agnocast_wake_signal(struct agnocast_proc *proc)
{
	struct eventfd_ctx *wake = READ_ONCE(proc->wake_eventfd);

	if (!wake)
		return;
#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 8, 0)
	eventfd_signal(wake);
#else
	eventfd_signal(wake, 1);
#endif
}

/* The subscriber's promise is broken (its topic's lock, or the namespace lock for write). */
void agnocast_wake_break(struct agnocast_subscriber *sub)
{
	WRITE_ONCE(sub->notified, false);
	agnocast_wake_signal(sub->ep.proc);
}

static void agnocast_wake_watchdog(struct timer_list *timer)
{
	struct agnocast_subscriber *sub = from_timer(sub, timer, watchdog);
	unsigned long due;

	if (!READ_ONCE(sub->notified))
		return;
	due = READ_ONCE(sub->notified_at) + AGNOCAST_WAKE_WATCHDOG_JIFFIES;
	if (time_before(jiffies, due)) {
		mod_timer(&sub->watchdog, due);
		return;
	}
	/* Under no lock: the flags are only read, and a signal is always safe. */
	agnocast_wake_signal(sub->ep.proc);
}

void agnocast_wake_sub_init(struct agnocast_subscriber *sub)
{
	timer_setup(&sub->watchdog, agnocast_wake_watchdog, 0);
}

/* Before the subscriber is freed: the watchdog neither runs nor re-arms. */
void agnocast_wake_sub_shutdown(struct agnocast_subscriber *sub)
{
#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 2, 0)
	timer_shutdown_sync(&sub->watchdog);
#else
	del_timer_sync(&sub->watchdog);
#endif
}

/*
 * @proc is dying (namespace lock held for write): every promise it made and
 * the subscriber has not seen kept yet is broken.
 */
void agnocast_wake_publisher_gone(struct agnocast_proc *proc)
{
	struct agnocast_endpoint *pub, *ep;
	struct agnocast_subscriber *sub;

	lockdep_assert_held_write(&proc->ns->lock);
	list_for_each_entry(pub, &proc->publishers, proc_node) {
		list_for_each_entry(ep, &pub->topic->subscribers, topic_node) {
			sub = agnocast_to_subscriber(ep);
			if (!sub->notified || sub->notifier != proc)
				continue;
			sub->notifier = NULL;
			agnocast_wake_break(sub);
		}
	}
}

/*
 * Gives @proc, which has none yet, the wake eventfd @wake and our reference
 * to it; it stays until the teardown, when no watchdog of the process's
 * subscribers can run any more.
 */
void agnocast_wake_set_eventfd(struct agnocast_proc *proc, struct eventfd_ctx *wake)
{
	WRITE_ONCE(proc->wake_eventfd, wake);
}

/* At teardown, once no subscriber of @proc is left to signal it. */
void agnocast_wake_put_eventfd(struct agnocast_proc *proc)
{
	struct eventfd_ctx *wake = xchg(&proc->wake_eventfd, NULL);

	if (wake)
		eventfd_ctx_put(wake);
}
