// Containers whose memory lives in the calling process's shared pool, so that
// a message holding them is readable in place by every subscriber.
#pragma once

#include <cstddef>
#include <limits>
#include <new>
#include <string>
#include <vector>

namespace agnocast {
namespace detail {

// Throws PoolExhausted when the pool has no room even after reclaiming.
void* pool_allocate(std::size_t bytes, std::size_t align);
void pool_deallocate(void* ptr) noexcept;

}  // namespace detail

// Stateless and default-constructible: every instance allocates from the pool
// of the process that calls it, which makes containers nest at any depth.
template <class T>
class allocator {
 public:
  using value_type = T;

  allocator() noexcept = default;
  template <class U>
  allocator(const allocator<U>&) noexcept {}

  T* allocate(std::size_t count) {
    if (count > std::numeric_limits<std::size_t>::max() / sizeof(T)) {
      throw std::bad_array_new_length();
    }
    return static_cast<T*>(detail::pool_allocate(count * sizeof(T), alignof(T)));
  }
  void deallocate(T* ptr, std::size_t) noexcept { detail::pool_deallocate(ptr); }

  template <class U>
  friend bool operator==(const allocator&, const allocator<U>&) noexcept {
    return true;
  }
};

template <class T>
using vector = std::vector<T, allocator<T>>;
using string = std::basic_string<char, std::char_traits<char>, allocator<char>>;

}  // namespace agnocast
