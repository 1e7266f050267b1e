// Loan scopes and the pool as the allocation hook sees them (heap_scope.hpp).
#include "memory/heap_hook.hpp"

#include <dlfcn.h>

#include <string>

#include "agnocast/allocator.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/heap_scope.hpp"
#include "heaphook_interface.h"
#include "kernel/runtime.hpp"
#include "tracing/trace.hpp"

namespace agnocast::detail {
namespace {

using GetInterface = const agnocast_heaphook_interface* (*)();

// The hook counts only when it is the malloc every library calls: loaded but
// preceded by another allocator (or dlopen'ed locally), it would route nothing.
const agnocast_heaphook_interface* find_hook() noexcept {
  auto get =
      reinterpret_cast<GetInterface>(::dlsym(RTLD_DEFAULT, "agnocast_heaphook_get_interface"));
  if (!get) return nullptr;
  const agnocast_heaphook_interface* hook = get();
  if (hook->version != AGNOCAST_HEAPHOOK_INTERFACE_VERSION) return nullptr;
  if (::dlsym(RTLD_DEFAULT, "malloc") != reinterpret_cast<void*>(hook->malloc)) return nullptr;
  return hook;
}

const agnocast_heaphook_interface* hook() noexcept {
  static const agnocast_heaphook_interface* const found = find_hook();
  return found;
}

// The pool functions the hook calls, with its routing off on this thread.
void* allocate_for_hook(std::size_t size, std::size_t align) noexcept {
  try {
    return pool_allocate(size, align);  // counted for the bandwidth counter, as agnocast::vector
  } catch (...) {
    return nullptr;  // the hook reports ENOMEM / std::bad_alloc
  }
}

void deallocate_for_hook(void* ptr) noexcept { pool_deallocate(ptr); }

std::size_t usable_size_for_hook(const void* ptr) noexcept {
  Runtime* runtime = Runtime::current();
  return runtime ? runtime->usable_size(ptr) : 0;
}

}  // namespace

void attach_pool_to_heap_hook(void* begin, std::size_t size) noexcept {
  if (const agnocast_heaphook_interface* found = hook()) {
    const agnocast_heaphook_pool pool{reinterpret_cast<std::uintptr_t>(begin), size,
                                      allocate_for_hook, deallocate_for_hook, usable_size_for_hook};
    found->attach_pool(&pool);
  }
}

void* enter_heap_scope() {
  const agnocast_heaphook_interface* found = hook();
  if (!found) return nullptr;
  Runtime::get();  // the pool exists (and the hook knows it) before anything is routed
  void* token = found->enter_scope();
  AGNOCAST_TRACE(agnocast_heap_scope_enter, token);
  return token;
}

void leave_heap_scope(void* token) noexcept {
  if (!token) return;
  AGNOCAST_TRACE(agnocast_heap_scope_exit, token);
  hook()->leave_scope(token);
}

void require_heap_hook(std::string_view type_name) {
  if (hook()) return;
  throw Error("agnocast: " + std::string(type_name) +
              " keeps std::vector/std::string members (AGNOCAST_HEAP_MESSAGE), which only the "
              "allocation hook places in shared memory, and it is not active in this process: "
              "run the program with LD_PRELOAD=libagnocast_heaphook.so, or link it with "
              "agnocast::heaphook (CMake); or declare the type with agnocast::vector/"
              "agnocast::string members and AGNOCAST_MESSAGE");
}

}  // namespace agnocast::detail

namespace agnocast {

heap_scope::heap_scope() : token_(detail::enter_heap_scope()) {}
heap_scope::~heap_scope() { detail::leave_heap_scope(token_); }
bool heap_scope::hook_active() noexcept { return detail::hook() != nullptr; }

}  // namespace agnocast
