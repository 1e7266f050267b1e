// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: pool slots and the pool files handed to subscribers.
 *
 * Slot i of a namespace is the range pool_base + i * pool_size, the same in
 * every process.  A slot is reused once its owner is gone and no entry lives
 * in its pool: then nobody reads from it any more.  Subscribers may still map
 * the old pool, but only at that range in their own address space, which a
 * registered process never receives as its own slot (it has one already;
 * libagnocast's fork child unmaps the views it inherited, and a process that
 * kept one would fail to map its own pool there rather than alias it).
 * Freeing a pool clears its bit in every process's given map, so a
 * subscriber is handed the slot's next pool before it reads an entry there,
 * and replaces its stale view.
 *
 * The owner attaches a sealed memfd: the seals (AGNOCAST_POOL_SEALS) leave
 * the owner's existing writable mapping as the only way to write the pool,
 * whoever opens the file and however (a reopening through /proc/<pid>/fd
 * included).  The kernel keeps only a read-only reopening of it, so whoever
 * receives it can never map the pool writable.
 *
 * Slots and pools change under the namespace lock (agnocast_ns.lock) held
 * for write.  Under it held for read, the data path counts entries in a pool
 * (atomically) and sets bits of a process's given map (atomic bit
 * operations).  A pool whose owner is gone and whose last entry goes under
 * the read lock is freed by the next agnocast_leave(), which takes the lock
 * for write.
 */
#include <linux/bitmap.h>
#include <linux/fcntl.h>
#include <linux/file.h>
#include <linux/fs.h>
#include <linux/magic.h>
#include <linux/pid.h>
#include <linux/pid_namespace.h>
#include <linux/sched.h>
#include <linux/shmem_fs.h>
#include <linux/slab.h>

#include "agnocast_internal.h"

struct agnocast_mempool *agnocast_pool_reserve(struct agnocast_ns *ns,
					       struct agnocast_proc *owner)
{
	struct agnocast_mempool *pool;
	unsigned long slot;

	lockdep_assert_held_write(&ns->lock);
	slot = find_first_zero_bit(ns->slot_map, agnocast_pool_count);
	if (slot >= agnocast_pool_count)
		return ERR_PTR(-ENOSPC);
	pool = kzalloc(sizeof(*pool), GFP_KERNEL_ACCOUNT);
	if (!pool)
		return ERR_PTR(-ENOMEM);
	pool->slot = slot;
	pool->size = agnocast_pool_size;
	pool->addr = agnocast_pool_base + slot * agnocast_pool_size;
	pool->owner = owner;
	pool->owner_pid = get_task_pid(current, PIDTYPE_TGID);
	set_bit(slot, ns->slot_map);
	ns->slots[slot] = pool;
	return pool;
}

static_assert(AGNOCAST_POOL_SEALS ==
	      (F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_FUTURE_WRITE | F_SEAL_SEAL));

/* Seals that make a pool unwritable but through existing writable mappings. */
static bool agnocast_pool_sealed(struct inode *inode)
{
	/* F_SEAL_WRITE (no writable mapping at all) is stronger than FUTURE_WRITE. */
	unsigned int seals = READ_ONCE(SHMEM_I(inode)->seals);

	if (seals & F_SEAL_WRITE)
		seals |= F_SEAL_FUTURE_WRITE;
	return (seals & AGNOCAST_POOL_SEALS) == AGNOCAST_POOL_SEALS;
}

int agnocast_pool_attach(struct agnocast_mempool *pool, int fd)
{
	struct file *file, *ro;
	struct inode *inode;
	int ret = -EINVAL;

	if (pool->file)
		return -EBUSY;
	file = fget(fd);
	if (!file)
		return -EBADF;
	inode = file_inode(file);
	/* Never hand out a read descriptor to what the owner cannot read. */
	if (!IS_ENABLED(CONFIG_SHMEM) || !(file->f_mode & FMODE_READ) || !S_ISREG(inode->i_mode) ||
	    inode->i_sb->s_magic != TMPFS_MAGIC || i_size_read(inode) < pool->size)
		goto out_put;
	ret = -EPERM;
	if (!agnocast_pool_sealed(inode))
		goto out_put;

	ro = dentry_open(&file->f_path, O_RDONLY | O_LARGEFILE, current_cred());
	if (IS_ERR(ro)) {
		ret = PTR_ERR(ro);
		goto out_put;
	}
	pool->file = ro;
	ret = 0;
out_put:
	fput(file);
	return ret;
}

static void agnocast_pool_free(struct agnocast_ns *ns, struct agnocast_mempool *pool)
{
	struct agnocast_proc *proc;

	list_for_each_entry(proc, &ns->procs, ns_node)
		clear_bit(pool->slot, proc->given);
	clear_bit(pool->slot, ns->slot_map);
	ns->slots[pool->slot] = NULL;
	if (pool->file)
		fput(pool->file);
	put_pid(pool->owner_pid);
	kfree(pool);
}

/* The owner is gone: the pool lives on while entries in it do. */
void agnocast_pool_orphan(struct agnocast_ns *ns, struct agnocast_mempool *pool)
{
	lockdep_assert_held_write(&ns->lock);
	pool->owner = NULL;
	list_add_tail(&pool->orphan_node, &ns->orphan_pools);
	ns->collect_pools = true;
}

/* Frees the ownerless pools no entry lives in any more. */
void agnocast_pools_collect(struct agnocast_ns *ns)
{
	struct agnocast_mempool *pool, *tmp;

	lockdep_assert_held_write(&ns->lock);
	ns->collect_pools = false;
	list_for_each_entry_safe(pool, tmp, &ns->orphan_pools, orphan_node) {
		if (atomic_long_read(&pool->entries))
			continue;
		list_del(&pool->orphan_node);
		agnocast_pool_free(ns, pool);
	}
}

/* Whether @proc must be given @pool's file to read entries in it. */
bool agnocast_pool_needs_giving(const struct agnocast_proc *proc,
				const struct agnocast_mempool *pool)
{
	return pool->owner != proc && !test_bit(pool->slot, proc->given);
}

/* Describes @pool for a subscriber; the descriptor comes later. */
void agnocast_pool_describe(struct agnocast_mempool *pool, struct agnocast_pool *out)
{
	memset(out, 0, sizeof(*out));
	out->addr = pool->addr;
	out->size = pool->size;
	out->fd = -1;
	out->pid = pid_nr_ns(pool->owner_pid, task_active_pid_ns(current));
}

/*
 * @proc now has a descriptor of @file, described by @granted: the pool is
 * given if it is still the slot's pool (the file reference the caller holds
 * keeps the file, and so the comparison, unambiguous).
 */
void agnocast_pool_mark_given(struct agnocast_proc *proc, const struct agnocast_pool *granted,
			      struct file *file)
{
	unsigned long slot = (granted->addr - agnocast_pool_base) / agnocast_pool_size;
	struct agnocast_mempool *pool = proc->ns->slots[slot];

	lockdep_assert_held(&proc->ns->lock);
	if (pool && pool->file == file)
		set_bit(slot, proc->given);
}

/* Teardown: @proc no longer maps any pool it was given. */
void agnocast_pool_drop_given(struct agnocast_proc *proc)
{
	lockdep_assert_held_write(&proc->ns->lock);
	bitmap_zero(proc->given, agnocast_pool_count);
}
