// SPDX-License-Identifier: GPL-2.0
/*
 * Test-bed self-test only, never shipped: a module whose load makes the
 * kernel print one class of report (parameter "report"), so the VM suite can
 * prove it fails on each.  Everything but "warning" needs the debug kernel's
 * checkers.
 */
#include <linux/bug.h>
#include <linux/delay.h>
#include <linux/module.h>
#include <linux/mutex.h>
#include <linux/slab.h>
#include <linux/spinlock.h>

static char *report = "warning";
module_param(report, charp, 0444);
MODULE_PARM_DESC(report, "warning, lockdep, atomic_sleep, kasan, ubsan or kmemleak");

static DEFINE_MUTEX(testbed_first);
static DEFINE_MUTEX(testbed_second);
static DEFINE_SPINLOCK(testbed_spin);

/* Both orders of two mutexes: lockdep's possible circular locking. */
static void testbed_lockdep(void)
{
	mutex_lock(&testbed_first);
	mutex_lock(&testbed_second);
	mutex_unlock(&testbed_second);
	mutex_unlock(&testbed_first);

	mutex_lock(&testbed_second);
	mutex_lock(&testbed_first);
	mutex_unlock(&testbed_first);
	mutex_unlock(&testbed_second);
}

static void testbed_atomic_sleep(void)
{
	spin_lock(&testbed_spin);
	msleep(1);
	spin_unlock(&testbed_spin);
}

static void testbed_kasan(void)
{
	volatile size_t index = 16;
	char *buf = kmalloc(16, GFP_KERNEL);

	if (!buf)
		return;
	pr_info("testbed: read past the end: %d\n", buf[index]);
	kfree(buf);
}

static void testbed_ubsan(void)
{
	volatile int shift = 40;

	pr_info("testbed: shift out of bounds: %d\n", 1 << shift);
}

/* Leaks 64 bytes: the pointer is dropped once printed. */
static void testbed_kmemleak(void)
{
	void *leaked = kzalloc(64, GFP_KERNEL);

	pr_info("testbed: leaked %p\n", leaked);
}

static int __init testbed_report_init(void)
{
	if (!strcmp(report, "warning"))
		WARN(1, "agnocast test bed: deliberate warning\n");
	else if (!strcmp(report, "lockdep"))
		testbed_lockdep();
	else if (!strcmp(report, "atomic_sleep"))
		testbed_atomic_sleep();
	else if (!strcmp(report, "kasan"))
		testbed_kasan();
	else if (!strcmp(report, "ubsan"))
		testbed_ubsan();
	else if (!strcmp(report, "kmemleak"))
		testbed_kmemleak();
	else
		return -EINVAL;
	return 0;
}

static void __exit testbed_report_exit(void)
{
}

module_init(testbed_report_init);
module_exit(testbed_report_exit);
MODULE_LICENSE("GPL");
MODULE_DESCRIPTION("agnocast test bed: prints a chosen kernel report on load");
