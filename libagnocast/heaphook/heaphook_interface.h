/* What libagnocast and libagnocast_heaphook.so tell each other. The hook
 * exports agnocast_heaphook_get_interface(); libagnocast finds it with dlsym, so
 * neither library links the other. Private to the two: not installed. */
#ifndef AGNOCAST_HEAPHOOK_INTERFACE_H
#define AGNOCAST_HEAPHOOK_INTERFACE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define AGNOCAST_HEAPHOOK_INTERFACE_VERSION 1U

/* The process's pool as the hook uses it. Every function is called with the
 * hook's own routing off on the calling thread, so what they allocate
 * themselves comes from the normal allocator. */
struct agnocast_heaphook_pool {
  uintptr_t begin;
  size_t size;
  /* NULL when the pool has no room; never throws. align is a power of two. */
  void* (*allocate)(size_t size, size_t align);
  void (*deallocate)(void* ptr);
  size_t (*usable_size)(const void* ptr);
};

struct agnocast_heaphook_interface {
  uint32_t version;
  /* The hook's malloc: it routes only if the process's malloc is this one. */
  void* (*malloc)(size_t size);
  /* Copies *pool; allocations inside a scope go there from now on. */
  void (*attach_pool)(const struct agnocast_heaphook_pool* pool);
  /* Opens a scope on the calling thread; the token ends it, from any thread. */
  void* (*enter_scope)(void);
  void (*leave_scope)(void* token);
};

const struct agnocast_heaphook_interface* agnocast_heaphook_get_interface(void);

#ifdef __cplusplus
}
#endif

#endif
