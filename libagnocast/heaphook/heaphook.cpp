// libagnocast_heaphook.so: replaces the malloc family so that, on a thread
// inside a loan scope, allocations come from the process's agnocast pool
// (HeapRouter decides; this file only wires the symbols). glibc's own
// allocator is reached through its __libc_* entry points, which neither
// allocate nor come back here.
#include <dlfcn.h>
#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstddef>

#include "heap_router.hpp"
#include "heaphook_interface.h"

extern "C" {
void* __libc_malloc(std::size_t size) noexcept;
void __libc_free(void* ptr) noexcept;
void* __libc_calloc(std::size_t count, std::size_t size) noexcept;
void* __libc_realloc(void* ptr, std::size_t size) noexcept;
void* __libc_memalign(std::size_t align, std::size_t size) noexcept;
}

namespace agnocast::heaphook {
namespace {

using UsableSize = std::size_t (*)(void*);
std::atomic<UsableSize> glibc_usable_size{nullptr};

// glibc exports no __libc_ name for it: found once with dlsym, whose own
// allocations are ordinary ones (routing is off while it runs).
std::size_t system_usable_size(void* ptr) {
  UsableSize function = glibc_usable_size.load(std::memory_order_acquire);
  if (!function) {
    const int saved = errno;
    function = reinterpret_cast<UsableSize>(::dlsym(RTLD_NEXT, "malloc_usable_size"));
    errno = saved;
    if (!function) return 0;
    glibc_usable_size.store(function, std::memory_order_release);
  }
  return function(ptr);
}

void report_to_stderr(const char* line, std::size_t length) {
  const int saved = errno;
  (void)!::write(STDERR_FILENO, line, length);
  (void)!::write(STDERR_FILENO, "\n", 1);
  errno = saved;
}

constinit HeapRouter router{SystemHeap{__libc_malloc, __libc_free, __libc_calloc, __libc_realloc,
                                       __libc_memalign, system_usable_size, report_to_stderr}};

std::size_t page_size() {
  static const std::size_t size = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  return size;
}

void attach_pool(const agnocast_heaphook_pool* pool) { router.attach_pool(*pool); }

__attribute__((constructor)) void prepare() {
  // Before any scope opens, so that dlsym's own allocations are never routed.
  (void)system_usable_size(nullptr);
  // The child's only thread is the forking one: it leaves its scopes, and
  // the pool it shared with the parent is no longer where it may allocate.
  ::pthread_atfork(nullptr, nullptr, [] { router.retire_pool(); });
}

}  // namespace
}  // namespace agnocast::heaphook

using agnocast::heaphook::HeapRouter;
using agnocast::heaphook::router;

extern "C" {

// The exported malloc is an alias of this hidden name, so that the interface
// can hand out the hook's own address, whatever else interposes malloc.
__attribute__((visibility("hidden"))) void* agnocast_heaphook_malloc(std::size_t size) noexcept {
  return router.malloc(size);
}
void* malloc(std::size_t size) noexcept __attribute__((alias("agnocast_heaphook_malloc")));

void free(void* ptr) noexcept { router.free(ptr); }
void* calloc(std::size_t count, std::size_t size) noexcept { return router.calloc(count, size); }
void* realloc(void* ptr, std::size_t size) noexcept { return router.realloc(ptr, size); }
void* reallocarray(void* ptr, std::size_t count, std::size_t size) noexcept {
  std::size_t bytes;
  if (__builtin_mul_overflow(count, size, &bytes)) {
    errno = ENOMEM;
    return nullptr;
  }
  return router.realloc(ptr, bytes);
}
void* memalign(std::size_t align, std::size_t size) noexcept {
  return router.memalign(align, size);
}
void* aligned_alloc(std::size_t align, std::size_t size) noexcept {
  return router.memalign(align, size);
}
int posix_memalign(void** out, std::size_t align, std::size_t size) noexcept {
  return router.posix_memalign(out, align, size);
}
void* valloc(std::size_t size) noexcept {
  return router.memalign(agnocast::heaphook::page_size(), size);
}
void* pvalloc(std::size_t size) noexcept {
  const std::size_t page = agnocast::heaphook::page_size();
  if (size > SIZE_MAX - page) {
    errno = ENOMEM;
    return nullptr;
  }
  return router.memalign(page, (size + page - 1) & ~(page - 1));
}
std::size_t malloc_usable_size(void* ptr) noexcept { return router.usable_size(ptr); }

const agnocast_heaphook_interface* agnocast_heaphook_get_interface(void) {
  static constexpr struct agnocast_heaphook_interface interface {
    AGNOCAST_HEAPHOOK_INTERFACE_VERSION, agnocast_heaphook_malloc, agnocast::heaphook::attach_pool,
        HeapRouter::enter_scope, HeapRouter::leave_scope
  };
  return &interface;
}

}  // extern "C"
