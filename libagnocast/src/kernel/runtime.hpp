// The process's agnocast state: the kernel (the device, registered), its own
// writable pool with the allocator over it, and the publisher pools it has
// mapped read-only. Created lazily on first use, reset in a fork child.
#pragma once

#include <sys/types.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <span>

#include "kernel/kernel.hpp"
#include "memory/tlsf.hpp"

namespace agnocast::detail {

class Runtime {
 public:
  // The process's runtime, initialized on first call (throws what init throws).
  static Runtime& get();
  // The runtime if this process has one already, else nullptr; never initializes.
  static Runtime* current() noexcept;
  // A runtime over a caller-provided region, for native tests: with a kernel
  // (a FakeKernel) publishers and subscriptions work, without one only
  // allocation in the pool does.
  static Runtime& install_for_testing(void* region, std::size_t size,
                                      std::unique_ptr<Kernel> kernel = nullptr);

  Kernel& kernel() const { return *kernel_; }
  // The kernel's wake_fd() (-1 without a kernel): every executor watches it.
  int wake_fd() const { return kernel_ ? kernel_->wake_fd() : -1; }
  pid_t pid() const { return pid_; }

  // Throws PoolExhausted after a reclaim round could not make room.
  void* allocate(std::size_t size, std::size_t align);
  void deallocate(void* ptr) noexcept;
  bool owns(const void* ptr) const { return pool_.owns(ptr); }
  // Bytes usable at ptr, a live allocation of this pool.
  std::size_t usable_size(const void* ptr) const;
  Tlsf::Stats pool_stats() const;

  // Destroys and frees messages the kernel reported as no longer referenced.
  void free_reclaimed(std::span<const std::uint64_t> addresses) noexcept;
  // Keeps reclaimed messages to free at the next borrow (free_deferred()), so
  // that a publish returns as soon as its subscribers are woken; frees them now
  // when a batch already waits.
  void defer_free(std::span<const std::uint64_t> addresses) noexcept;
  // Frees what defer_free() kept: on every borrow, before reclaiming, and
  // before the pool is found exhausted.
  void free_deferred() noexcept;
  // Asks the kernel for every reclaimable message of this process and frees
  // it, with what waits in defer_free().
  void reclaim_all();

  // Maps a publisher's pool read-only at its address and closes grant.fd.
  void map_pool(const PoolGrant& grant);
  // The kernel hands a pool to this process once, to the RECEIVE or TAKE
  // that needs it first; another thread's call may then return entries in it
  // before the first thread has mapped it. Every RECEIVE and TAKE, and the
  // mapping of the pools it was handed, hold this: no entry is returned
  // before its pool is mapped.
  std::mutex& grant_mutex() { return grant_mutex_; }
  // The pool mapped here (a publisher's, or this process's own) that holds
  // `address`: all a reader of a message there may touch. Empty when none does.
  std::span<const std::byte> pool_holding(const void* address);

 private:
  Runtime(std::unique_ptr<Kernel> kernel, pid_t pid, void* pool_addr, std::size_t pool_size);
  static Runtime* create();
  static void forget_in_fork_child() noexcept;

  std::unique_ptr<Kernel> kernel_;  // absent only in native tests of allocation
  // False for a test runtime, whose region and kernel the test owns.
  bool pool_mapped_here_ = false;
  pid_t pid_;
  void* pool_addr_;
  std::size_t pool_size_;

  std::mutex grant_mutex_;

  mutable std::mutex pool_mutex_;
  Tlsf pool_;

  // One publish's reclaimed messages, freed at the next borrow.
  static constexpr std::size_t deferred_max = 64;
  std::mutex deferred_mutex_;
  std::array<std::uint64_t, deferred_max> deferred_;
  std::size_t deferred_count_ = 0;
  std::atomic<bool> deferred_waiting_{false};

  std::mutex mapped_mutex_;
  std::map<std::uint64_t, std::uint64_t> mapped_pools_;  // address -> size
};

// Pool bytes the calling thread has allocated so far, for the bandwidth
// counter of the messages it publishes (see published_bytes()).
const std::uint64_t& pool_bytes_allocated_by_this_thread() noexcept;

}  // namespace agnocast::detail
