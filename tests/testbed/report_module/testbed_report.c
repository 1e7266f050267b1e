// SPDX-License-Identifier: GPL-2.0
/*
 * Test-bed self-test only, never shipped: a module whose load triggers a
 * kernel WARN, so the VM suite can prove it fails on kernel warnings.
 */
#include <linux/bug.h>
#include <linux/module.h>

static int __init testbed_warn_init(void)
{
	WARN(1, "agnocast test bed: deliberate warning\n");
	return 0;
}

static void __exit testbed_warn_exit(void)
{
}

module_init(testbed_warn_init);
module_exit(testbed_warn_exit);
MODULE_LICENSE("GPL");
MODULE_DESCRIPTION("agnocast test bed: warns on load");
