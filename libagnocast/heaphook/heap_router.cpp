#include "heap_router.hpp"

#include <cerrno>
#include <cstring>

namespace agnocast::heaphook {
namespace {

// Initial-exec: reading it never calls __tls_get_addr, which may allocate.
thread_local ThreadScope this_thread __attribute__((tls_model("initial-exec")));

// What glibc's malloc guarantees on 64-bit targets, and what new expects.
constexpr std::size_t malloc_alignment = 16;

bool is_power_of_two(std::size_t value) { return value != 0 && (value & (value - 1)) == 0; }

std::size_t next_power_of_two(std::size_t value) {
  std::size_t power = 1;
  while (power < value && power != 0) power <<= 1;
  return power;
}

// Appends text or a decimal number to a fixed buffer, without allocating.
class Line {
 public:
  Line& operator<<(const char* text) {
    while (*text && length_ < sizeof(text_)) text_[length_++] = *text++;
    return *this;
  }
  Line& operator<<(std::size_t value) {
    char digits[24];
    int count = 0;
    do {
      digits[count++] = static_cast<char>('0' + value % 10);
      value /= 10;
    } while (value != 0);
    while (count > 0 && length_ < sizeof(text_)) text_[length_++] = digits[--count];
    return *this;
  }
  const char* data() const { return text_; }
  std::size_t size() const { return length_; }

 private:
  char text_[320];
  std::size_t length_ = 0;
};

}  // namespace

void HeapRouter::attach_pool(const agnocast_heaphook_pool& pool) noexcept {
  const agnocast_heaphook_pool* current = pool_.load(std::memory_order_acquire);
  agnocast_heaphook_pool* slot = current == &slots_[0] ? &slots_[1] : &slots_[0];
  *slot = pool;
  pool_.store(slot, std::memory_order_release);
}

void HeapRouter::retire_pool() noexcept {
  if (const agnocast_heaphook_pool* pool = pool_.exchange(nullptr)) {
    retired_begin_.store(pool->begin, std::memory_order_relaxed);
    retired_end_.store(pool->begin + pool->size, std::memory_order_relaxed);
  }
  reset_thread();
}

void* HeapRouter::enter_scope() noexcept {
  this_thread.depth.fetch_add(1, std::memory_order_relaxed);
  return &this_thread;
}

void HeapRouter::leave_scope(void* token) noexcept {
  static_cast<ThreadScope*>(token)->depth.fetch_sub(1, std::memory_order_relaxed);
}

bool HeapRouter::in_scope() noexcept {
  return this_thread.depth.load(std::memory_order_relaxed) > 0 && !this_thread.routing_off;
}

void HeapRouter::reset_thread() noexcept {
  this_thread.depth.store(0, std::memory_order_relaxed);
  this_thread.routing_off = false;
}

const agnocast_heaphook_pool* HeapRouter::routing_pool() const noexcept {
  if (!in_scope()) return nullptr;
  return pool_.load(std::memory_order_acquire);
}

const agnocast_heaphook_pool* HeapRouter::pool_owning(const void* ptr) const noexcept {
  const agnocast_heaphook_pool* pool = pool_.load(std::memory_order_acquire);
  const auto at = reinterpret_cast<std::uintptr_t>(ptr);
  return pool != nullptr && at >= pool->begin && at - pool->begin < pool->size ? pool : nullptr;
}

bool HeapRouter::in_pool(const void* ptr) const noexcept { return pool_owning(ptr) != nullptr; }

bool HeapRouter::in_retired(const void* ptr) const noexcept {
  const auto at = reinterpret_cast<std::uintptr_t>(ptr);
  return at >= retired_begin_.load(std::memory_order_relaxed) &&
         at < retired_end_.load(std::memory_order_relaxed);
}

void* HeapRouter::pool_allocate(const agnocast_heaphook_pool& pool, std::size_t size,
                                std::size_t align) noexcept {
  // The pool's own bookkeeping (a reclaim round, an exception it catches)
  // must not come back here.
  this_thread.routing_off = true;
  void* ptr =
      pool.allocate(size == 0 ? 1 : size, align < malloc_alignment ? malloc_alignment : align);
  this_thread.routing_off = false;
  if (ptr) return ptr;
  if (!exhaustion_reported_.exchange(true)) {
    Line line;
    line << "agnocast: the shared pool (" << pool.size << " bytes) has no room for " << size
         << " bytes allocated inside a loan scope: malloc returns NULL (ENOMEM) and new throws "
            "std::bad_alloc; raise the module parameter pool_size or hold fewer messages";
    system_.report(line.data(), line.size());
  }
  errno = ENOMEM;
  return nullptr;
}

void* HeapRouter::malloc(std::size_t size) noexcept {
  if (const agnocast_heaphook_pool* pool = routing_pool()) {
    return pool_allocate(*pool, size, malloc_alignment);
  }
  return system_.malloc(size);
}

void HeapRouter::free(void* ptr) noexcept {
  if (ptr == nullptr) return;
  if (const agnocast_heaphook_pool* pool = pool_owning(ptr)) {
    const bool was_off = this_thread.routing_off;
    this_thread.routing_off = true;
    pool->deallocate(ptr);
    this_thread.routing_off = was_off;
    return;
  }
  if (in_retired(ptr)) return;
  system_.free(ptr);
}

void* HeapRouter::calloc(std::size_t count, std::size_t size) noexcept {
  const agnocast_heaphook_pool* pool = routing_pool();
  if (!pool) return system_.calloc(count, size);
  std::size_t bytes;
  if (__builtin_mul_overflow(count, size, &bytes)) {
    errno = ENOMEM;
    return nullptr;
  }
  void* ptr = pool_allocate(*pool, bytes, malloc_alignment);
  if (ptr) std::memset(ptr, 0, bytes);  // pool blocks are reused, not fresh pages
  return ptr;
}

// Moves a block to where malloc would put it now, when that is another
// allocator than the one that owns it; otherwise lets the owner resize it.
void* HeapRouter::realloc(void* ptr, std::size_t size) noexcept {
  if (ptr == nullptr) return malloc(size);
  if (in_retired(ptr)) {  // its bytes are gone with the parent's pool
    errno = ENOMEM;
    return nullptr;
  }
  const bool from_pool = in_pool(ptr);
  const agnocast_heaphook_pool* target = routing_pool();
  if (!from_pool && !target) return system_.realloc(ptr, size);
  if (size == 0) {  // glibc frees and returns NULL
    free(ptr);
    return nullptr;
  }
  const std::size_t old_size = usable_size(ptr);
  void* moved = target ? pool_allocate(*target, size, malloc_alignment) : system_.malloc(size);
  if (!moved) return nullptr;  // the old block stays valid, as realloc promises
  std::memcpy(moved, ptr, old_size < size ? old_size : size);
  free(ptr);
  return moved;
}

void* HeapRouter::memalign(std::size_t align, std::size_t size) noexcept {
  const agnocast_heaphook_pool* pool = routing_pool();
  if (!pool) return system_.memalign(align, size);
  if (!is_power_of_two(align)) align = next_power_of_two(align);
  if (align == 0) {
    errno = EINVAL;
    return nullptr;
  }
  return pool_allocate(*pool, size, align);
}

int HeapRouter::posix_memalign(void** out, std::size_t align, std::size_t size) noexcept {
  if (!is_power_of_two(align) || align % sizeof(void*) != 0) return EINVAL;
  const int saved = errno;
  void* ptr = memalign(align, size);
  if (!ptr) return ENOMEM;
  errno = saved;  // posix_memalign reports through its result only
  *out = ptr;
  return 0;
}

std::size_t HeapRouter::usable_size(void* ptr) noexcept {
  if (ptr == nullptr || in_retired(ptr)) return 0;
  if (const agnocast_heaphook_pool* pool = pool_owning(ptr)) {
    const bool was_off = this_thread.routing_off;
    this_thread.routing_off = true;
    const std::size_t size = pool->usable_size(ptr);
    this_thread.routing_off = was_off;
    return size;
  }
  return system_.usable_size(ptr);
}

}  // namespace agnocast::heaphook
