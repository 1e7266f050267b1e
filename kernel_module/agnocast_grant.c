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
 *
 * While no lock is held the entries can go (dropped for newer ones, shed,
 * or released by a racing call) and their pool with them, its slot then
 * reused by another pool at the same address.  Commit therefore hands over
 * only the grants an entry of the call still needs: mapping a dead pool's
 * file at its address would hide the live pool there from the caller.
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

/* Sets installed grant @i aside, to be closed once no lock is held. */
static void agnocast_grants_withhold(struct agnocast_grants *grants, u32 i)
{
	grants->withheld_files[grants->withheld] = grants->files[i];
	grants->withheld_fds[grants->withheld++] = grants->out[i].fd;
}

/* Closes and puts the withheld grants; no lock held. */
static void agnocast_grants_close_withheld(struct agnocast_grants *grants)
{
	while (grants->withheld) {
		grants->withheld--;
		close_fd(grants->withheld_fds[grants->withheld]);
		fput(grants->withheld_files[grants->withheld]);
	}
}

/*
 * TAKE's one grant: the installed descriptor of a pool the newest entry no
 * longer needs is closed once no lock is held (agnocast_grants_install()).
 */
void agnocast_grants_add_over(struct agnocast_grants *grants, struct agnocast_mempool *pool)
{
	if (grants->count) {
		agnocast_grants_withhold(grants, 0);
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

	agnocast_grants_close_withheld(grants);
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

/* Whether one of @sub's unreceived entries @first..@first+@n-1 is in @file's pool. */
static bool agnocast_grant_needed(const struct file *file, const struct agnocast_subscriber *sub,
				  u32 first, u32 n)
{
	u32 i;

	for (i = first; i < first + n; i++) {
		if (agnocast_sub_unreceived(sub, i)->pool->file == file)
			return true;
	}
	return false;
}

/*
 * Keeps, in order, the grants whose pool holds one of @sub's unreceived
 * entries @first..@first+@n-1 (those the call hands over) and marks them
 * given; withholds the others.  Namespace and topic locks held.
 */
void agnocast_grants_commit(struct agnocast_proc *proc, struct agnocast_grants *grants,
			    const struct agnocast_subscriber *sub, u32 first, u32 n)
{
	u32 i, kept = 0;

	for (i = 0; i < grants->count; i++) {
		if (!agnocast_grant_needed(grants->files[i], sub, first, n)) {
			agnocast_grants_withhold(grants, i);
			continue;
		}
		agnocast_pool_mark_given(proc, &grants->out[i], grants->files[i]);
		grants->files[kept] = grants->files[i];
		grants->out[kept++] = grants->out[i];
	}
	grants->count = kept;
}

/* Drops the call's references; no lock held. */
void agnocast_grants_put(struct agnocast_grants *grants)
{
	u32 i;

	agnocast_grants_close_withheld(grants);
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

