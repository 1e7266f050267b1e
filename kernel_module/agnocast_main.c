// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: module parameters, the /dev/agnocast device and ioctl dispatch.
 *
 * The ioctl handler is a thin switch into the handlers (agnocast_admin.c,
 * agnocast_ioctl.c, agnocast_introspect.c), each of which copies its own
 * argument in and out.  Every open file
 * holds a user reference on the opener's namespace state, which read() and
 * poll() use for exit records, and whether its opener may read them.
 */
#include <linux/capability.h>
#include <linux/fs.h>
#include <linux/ipc_namespace.h>
#include <linux/miscdevice.h>
#include <linux/mm.h>
#include <linux/nsproxy.h>
#include <linux/slab.h>
#include <linux/module.h>
#include <linux/overflow.h>
#include <linux/poll.h>
#include <linux/uaccess.h>

#include "agnocast_internal.h"
/* The one place the trace events are defined. */
#define CREATE_TRACE_POINTS
#include "agnocast_trace.h"

unsigned long agnocast_pool_size = 1UL << 30;
module_param_named(pool_size, agnocast_pool_size, ulong, 0444);
MODULE_PARM_DESC(pool_size, "Bytes per process pool (page multiple, default 1 GiB)");

unsigned int agnocast_pool_count = 1024;
module_param_named(pool_count, agnocast_pool_count, uint, 0444);
MODULE_PARM_DESC(pool_count, "Pool slots per IPC namespace (default 1024)");

/*
 * 32 TiB: above AddressSanitizer's shadow memory (which ends at
 * 0x10007fff8000), so programs built with it map pools where the module puts
 * them.
 */
unsigned long agnocast_pool_base = 0x200000000000UL;
module_param_named(pool_base, agnocast_pool_base, ulong, 0444);
MODULE_PARM_DESC(pool_base, "Address of slot 0 (page aligned, default 0x200000000000)");

unsigned int agnocast_max_endpoints_per_process = 1024;
module_param_named(max_endpoints_per_process, agnocast_max_endpoints_per_process, uint, 0444);
MODULE_PARM_DESC(max_endpoints_per_process,
		 "Publishers plus subscribers one process may have (default 1024)");

unsigned int agnocast_max_held_per_subscriber = 4096;
module_param_named(max_held_per_subscriber, agnocast_max_held_per_subscriber, uint, 0444);
MODULE_PARM_DESC(max_held_per_subscriber,
		 "Entries one subscriber may hold, received and not released (default 4096)");

unsigned int agnocast_max_topics_per_namespace = 4096;
module_param_named(max_topics_per_namespace, agnocast_max_topics_per_namespace, uint, 0444);
MODULE_PARM_DESC(max_topics_per_namespace, "Topics one IPC namespace may have (default 4096)");

/* Keeps bitmaps and slot tables of a namespace reasonably small. */
#define AGNOCAST_POOL_COUNT_MAX 65536
/* Lowest user address a pool may start at: far above any mmap_min_addr. */
#define AGNOCAST_POOL_BASE_MIN (1UL << 32)

static int agnocast_params_valid(void)
{
	unsigned long span, end;

	if (!agnocast_pool_size || !PAGE_ALIGNED(agnocast_pool_size)) {
		pr_err("agnocast: pool_size=%lu must be a nonzero multiple of %lu\n",
		       agnocast_pool_size, PAGE_SIZE);
		return -EINVAL;
	}
	if (!agnocast_pool_count || agnocast_pool_count > AGNOCAST_POOL_COUNT_MAX) {
		pr_err("agnocast: pool_count=%u must be within 1..%u\n",
		       agnocast_pool_count, AGNOCAST_POOL_COUNT_MAX);
		return -EINVAL;
	}
	if (!agnocast_max_endpoints_per_process || !agnocast_max_held_per_subscriber ||
	    !agnocast_max_topics_per_namespace) {
		pr_err("agnocast: max_endpoints_per_process=%u, max_held_per_subscriber=%u and max_topics_per_namespace=%u must be at least 1\n",
		       agnocast_max_endpoints_per_process, agnocast_max_held_per_subscriber,
		       agnocast_max_topics_per_namespace);
		return -EINVAL;
	}
	if (!PAGE_ALIGNED(agnocast_pool_base) || agnocast_pool_base < AGNOCAST_POOL_BASE_MIN) {
		pr_err("agnocast: pool_base=%#lx must be page aligned and at least %#lx\n",
		       agnocast_pool_base, AGNOCAST_POOL_BASE_MIN);
		return -EINVAL;
	}
	if (check_mul_overflow(agnocast_pool_size, (unsigned long)agnocast_pool_count, &span) ||
	    check_add_overflow(agnocast_pool_base, span, &end) || end > DEFAULT_MAP_WINDOW) {
		pr_err("agnocast: pool_base=%#lx + pool_count=%u * pool_size=%lu exceeds the user address space (%#lx)\n",
		       agnocast_pool_base, agnocast_pool_count, agnocast_pool_size,
		       DEFAULT_MAP_WINDOW);
		return -EINVAL;
	}
	return 0;
}

static int agnocast_get_version(void __user *uarg)
{
	struct agnocast_version version = {
		.major = AGNOCAST_VERSION_MAJOR,
		.minor = AGNOCAST_VERSION_MINOR,
		.patch = AGNOCAST_VERSION_PATCH,
	};

	return copy_to_user(uarg, &version, sizeof(version)) ? -EFAULT : 0;
}

static long agnocast_ioctl(struct file *file, unsigned int cmd, unsigned long arg)
{
	struct agnocast_file *af = file->private_data;
	struct agnocast_ns *ns = af->ns;
	void __user *uarg = (void __user *)arg;

	switch (cmd) {
	case AGNOCAST_IOC_GET_VERSION:
		return agnocast_get_version(uarg);
	case AGNOCAST_IOC_REGISTER_PROCESS:
		return agnocast_register_process(ns, uarg);
	case AGNOCAST_IOC_UNREGISTER_PROCESS:
		return agnocast_unregister_process(ns);
	case AGNOCAST_IOC_ADD_PUBLISHER:
		return agnocast_add_publisher(ns, uarg);
	case AGNOCAST_IOC_REMOVE_PUBLISHER:
		return agnocast_remove_publisher(ns, uarg);
	case AGNOCAST_IOC_ADD_SUBSCRIBER:
		return agnocast_add_subscriber(ns, uarg);
	case AGNOCAST_IOC_REMOVE_SUBSCRIBER:
		return agnocast_remove_subscriber(ns, uarg);
	case AGNOCAST_IOC_PUBLISH:
		return agnocast_publish(ns, uarg);
	case AGNOCAST_IOC_RECLAIM:
		return agnocast_reclaim(ns, uarg);
	case AGNOCAST_IOC_RECEIVE:
		return agnocast_receive(ns, uarg);
	case AGNOCAST_IOC_TAKE:
		return agnocast_take(ns, uarg);
	case AGNOCAST_IOC_RELEASE:
		return agnocast_release(ns, uarg);
	case AGNOCAST_IOC_LIST_TOPICS:
		return agnocast_list_topics(ns, uarg);
	case AGNOCAST_IOC_TOPIC_INFO:
		return agnocast_topic_info(ns, uarg);
	case AGNOCAST_IOC_LIST_PROCESSES:
		return agnocast_list_processes(ns, uarg);
	case AGNOCAST_IOC_SHED:
		return agnocast_shed(ns, uarg);
	case AGNOCAST_IOC_SET_POLICY:
		return agnocast_set_policy(ns, uarg);
	case AGNOCAST_IOC_GET_POLICY:
		return agnocast_get_policy(ns, uarg);
	case AGNOCAST_IOC_TOPIC_SCHEMA:
		return agnocast_topic_schema(ns, uarg);
	case AGNOCAST_IOC_NOTIFY_FAILED:
		return agnocast_notify_failed(ns, uarg);
	default:
		return -ENOTTY;
	}
}

static int agnocast_dev_open(struct inode *inode, struct file *file)
{
	struct agnocast_file *af;

	af = kzalloc(sizeof(*af), GFP_KERNEL_ACCOUNT);
	if (!af)
		return -ENOMEM;
	af->ns = agnocast_ns_get_current();
	if (!af->ns) {
		kfree(af);
		return -ENOMEM;
	}
	/*
	 * Like a file's permissions, decided by the opener: a descriptor
	 * passed on or kept across setuid() reads what its opener could.
	 */
	af->may_read_exit_records =
		ns_capable_noaudit(current->nsproxy->ipc_ns->user_ns, CAP_SYS_ADMIN);
	file->private_data = af;
	return 0;
}

static int agnocast_dev_release(struct inode *inode, struct file *file)
{
	struct agnocast_file *af = file->private_data;

	agnocast_ns_put(af->ns);
	kfree(af);
	return 0;
}

static ssize_t agnocast_dev_read(struct file *file, char __user *buf, size_t count, loff_t *ppos)
{
	struct agnocast_file *af = file->private_data;

	if (!af->may_read_exit_records)
		return -EPERM;
	return agnocast_read_exit_records(af->ns, buf, count, file->f_flags & O_NONBLOCK);
}

static __poll_t agnocast_dev_poll(struct file *file, poll_table *wait)
{
	struct agnocast_ns *ns = ((struct agnocast_file *)file->private_data)->ns;

	poll_wait(file, &ns->exit_wait, wait);
	return agnocast_exit_records_waiting(ns) ? EPOLLIN | EPOLLRDNORM : 0;
}

static const struct file_operations agnocast_fops = {
	.owner = THIS_MODULE,
	.open = agnocast_dev_open,
	.release = agnocast_dev_release,
	.read = agnocast_dev_read,
	.poll = agnocast_dev_poll,
	.unlocked_ioctl = agnocast_ioctl,
	/* No compat_ioctl: pools live above 4 GiB, out of a 32-bit process's reach. */
	.llseek = noop_llseek,
};

static struct miscdevice agnocast_misc = {
	.minor = MISC_DYNAMIC_MINOR,
	.name = "agnocast",
	.fops = &agnocast_fops,
	/* Group access comes from the udev rule (group agnocast). */
	.mode = 0660,
};

/* Each step is undone by agnocast_exit() in reverse order, and here on failure. */
static int __init agnocast_init(void)
{
	int ret;

	ret = agnocast_params_valid();
	if (ret)
		return ret;
	ret = agnocast_entry_init();
	if (ret)
		return ret;
	agnocast_ns_init();
	ret = agnocast_process_init();
	if (ret)
		goto err_ns_exit;
	ret = misc_register(&agnocast_misc);
	if (ret) {
		pr_err("agnocast: cannot register /dev/agnocast: %d\n", ret);
		goto err_process_exit;
	}
	return 0;

err_process_exit:
	agnocast_process_exit();
err_ns_exit:
	agnocast_ns_exit();
	agnocast_entry_exit();
	return ret;
}

static void __exit agnocast_exit(void)
{
	misc_deregister(&agnocast_misc);
	/* Teardowns still queued end here, before the states they use go. */
	agnocast_process_exit();
	agnocast_ns_exit();
	agnocast_entry_exit();
}

module_init(agnocast_init);
module_exit(agnocast_exit);

MODULE_LICENSE("GPL");
MODULE_DESCRIPTION("agnocast: zero-copy publish/subscribe bookkeeping");
MODULE_VERSION(__stringify(AGNOCAST_VERSION_MAJOR) "." __stringify(
	AGNOCAST_VERSION_MINOR) "." __stringify(AGNOCAST_VERSION_PATCH));
