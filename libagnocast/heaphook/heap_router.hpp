// The decisions of the allocation hook, apart from the symbols that replace
// malloc: where an allocation goes (the pool inside a loan scope, the normal
// allocator outside) and who owns a pointer handed back (the pool's address
// range decides). The normal allocator and the pool are function tables, so
// native tests drive the router with fakes.
//
// Nothing here allocates: these functions run inside malloc.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "heaphook_interface.h"

namespace agnocast::heaphook {

// The allocator that serves everything outside a scope (glibc's in the hook).
struct SystemHeap {
  void* (*malloc)(std::size_t size);
  void (*free)(void* ptr);
  void* (*calloc)(std::size_t count, std::size_t size);
  void* (*realloc)(void* ptr, std::size_t size);
  void* (*memalign)(std::size_t align, std::size_t size);
  std::size_t (*usable_size)(void* ptr);
  // Writes one line (without its newline) where the user sees it.
  void (*report)(const char* line, std::size_t length);
};

// A thread's loan scopes; other threads may end them through enter()'s token.
struct ThreadScope {
  std::atomic<int> depth{0};
  bool routing_off = false;  // set while the router itself calls the pool
};

class HeapRouter {
 public:
  constexpr explicit HeapRouter(const SystemHeap& system) noexcept : system_(system) {}

  // The process's pool, from now on. The first call happens before any
  // pointer of the pool reaches free (libagnocast attaches on creating it).
  void attach_pool(const agnocast_heaphook_pool& pool) noexcept;
  // In a fork child: the pool is no longer this process's. Scopes end; frees
  // of its pointers are ignored (the memory is gone), nothing new goes there.
  void retire_pool() noexcept;

  // Opens a scope on the calling thread; the token closes it.
  static void* enter_scope() noexcept;
  static void leave_scope(void* token) noexcept;
  static bool in_scope() noexcept;
  // Ends every scope of the calling thread (a fork child's only thread).
  static void reset_thread() noexcept;

  void* malloc(std::size_t size) noexcept;
  void free(void* ptr) noexcept;
  void* calloc(std::size_t count, std::size_t size) noexcept;
  void* realloc(void* ptr, std::size_t size) noexcept;
  // align: any value, rounded up to a power of two as glibc's memalign does.
  void* memalign(std::size_t align, std::size_t size) noexcept;
  // 0 or EINVAL/ENOMEM, as POSIX says.
  int posix_memalign(void** out, std::size_t align, std::size_t size) noexcept;
  std::size_t usable_size(void* ptr) noexcept;

  bool in_pool(const void* ptr) const noexcept;

 private:
  // The pool allocations go to now, or nullptr: outside a scope, or none attached.
  const agnocast_heaphook_pool* routing_pool() const noexcept;
  // The attached pool if ptr lies in it, else nullptr.
  const agnocast_heaphook_pool* pool_owning(const void* ptr) const noexcept;
  void* pool_allocate(const agnocast_heaphook_pool& pool, std::size_t size,
                      std::size_t align) noexcept;
  bool in_retired(const void* ptr) const noexcept;

  SystemHeap system_;
  // Two slots, so that a new pool is filled in before readers see it.
  agnocast_heaphook_pool slots_[2] = {};
  std::atomic<const agnocast_heaphook_pool*> pool_{nullptr};
  std::atomic<std::uintptr_t> retired_begin_{0};
  std::atomic<std::uintptr_t> retired_end_{0};
  std::atomic<bool> exhaustion_reported_{false};
};

}  // namespace agnocast::heaphook
