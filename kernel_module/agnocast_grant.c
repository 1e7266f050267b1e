// SPDX-License-Identifier: GPL-2.0
/*
 * agnocast: access grants, the pools handed to a subscriber by RECEIVE and
 * TAKE.
 *
 * A subscriber reads an entry in a pool that is neither its own nor given to
 * it only after it receives a descriptor of the pool's read-only file.
 * Descriptors are installed with receive_fd() (the kernel's path for passing
 * files, with its security check) while no lock is held, before the entries
 * that need them are committed: a call that needs a pool the caller lacks
 * takes a reference on its file, drops the namespace lock, installs, and
 * locks again.  Entries are then received only up to the first one whose
 * pool is neither the caller's nor given to it.  Once the call commits, the
 * pools are marked given (agnocast_pool.c); a call that fails closes what it
 * installed.
 */
#include <linux/fdtable.h>
#include <linux/file.h>
#include <linux/version.h>

#include "agnocast_internal.h"

static bool agnocast_grants_has(const struct agnocast_grants *grants,
				const struct agnocast_mempool *pool)
{
	u32 i;

	for (i = 0; i < grants->count; i++) {
		if (grants->files[i] == pool->file)
			return true;
	}
	return false;
}

/* Whether @proc can read @pool once the grants are committed. */
bool agnocast_grants_readable(const struct agnocast_proc *proc,
			      const struct agnocast_grants *grants,
			      const struct agnocast_mempool *pool)
{
	return !agnocast_pool_needs_giving(proc, pool) || agnocast_grants_has(grants, pool);
}

/* Adds @pool to the grants to install; false when they are full. */
bool agnocast_grants_add(struct agnocast_grants *grants, struct agnocast_mempool *pool)
{
	if (grants->count == grants->capacity)
		return false;
	agnocast_pool_describe(pool, &grants->out[grants->count]);
	grants->files[grants->count++] = get_file(pool->file);
	return true;
}

/*
 * TAKE's one grant: the installed descriptor of a pool the newest entry no
 * longer needs is closed once no lock is held (agnocast_grants_install()).
 */
void agnocast_grants_add_over(struct agnocast_grants *grants, struct agnocast_mempool *pool)
{
	if (grants->count) {
		grants->stale_fd = grants->out[0].fd;
		grants->stale_file = grants->files[0];
		grants->count = 0;
	}
	agnocast_grants_add(grants, pool);
}

static int agnocast_receive_fd(struct file *file)
{
#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 8, 0)
	return receive_fd(file, NULL, O_CLOEXEC);
#else
	return receive_fd(file, O_CLOEXEC);
#endif
}

/*
 * Installs grants @from.. (no lock held); on failure closes and forgets
 * what this call to it added.
 */
int agnocast_grants_install(struct agnocast_grants *grants, u32 from)
{
	u32 i;
	int fd;

	if (grants->stale_file) {
		close_fd(grants->stale_fd);
		fput(grants->stale_file);
		grants->stale_file = NULL;
	}
	for (i = from; i < grants->count; i++) {
		fd = agnocast_receive_fd(grants->files[i]);
		if (fd < 0)
			goto err_undo;
		grants->out[i].fd = fd;
	}
	return 0;

err_undo:
	while (i-- > from)
		close_fd(grants->out[i].fd);
	for (i = from; i < grants->count; i++)
		fput(grants->files[i]);
	grants->count = from;
	return fd;
}

/* Marks the granted pools given (those still alive); namespace lock held. */
void agnocast_grants_commit(struct agnocast_proc *proc, const struct agnocast_grants *grants)
{
	u32 i;

	for (i = 0; i < grants->count; i++)
		agnocast_pool_mark_given(proc, &grants->out[i], grants->files[i]);
}

void agnocast_grants_put(struct agnocast_grants *grants)
{
	u32 i;

	for (i = 0; i < grants->count; i++)
		fput(grants->files[i]);
}

/* Closes installed descriptors of a call that failed after installing them. */
void agnocast_grants_close(struct agnocast_grants *grants)
{
	u32 i;

	for (i = 0; i < grants->count; i++)
		close_fd(grants->out[i].fd);
}

