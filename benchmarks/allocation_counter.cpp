#include "allocation_counter.hpp"

#include <cstdlib>
#include <new>

namespace {
thread_local std::uint64_t allocations = 0;
}  // namespace

namespace agnocast::bench {
std::uint64_t allocations_by_this_thread() { return allocations; }
}  // namespace agnocast::bench

// The standard's replaceable allocation function; the library's operator
// delete (free) stays as it is, and new[] and nothrow new call this one.
void* operator new(std::size_t size) {
  ++allocations;
  if (void* memory = std::malloc(size ? size : 1)) return memory;
  throw std::bad_alloc();
}
