// The pool allocation behind agnocast::vector and agnocast::string (allocator.hpp).
#include "agnocast/allocator.hpp"

#include "kernel/runtime.hpp"

namespace agnocast::detail {
namespace {
thread_local std::uint64_t pool_bytes_of_this_thread = 0;
}  // namespace

const std::uint64_t& pool_bytes_allocated_by_this_thread() noexcept {
  return pool_bytes_of_this_thread;
}

void* pool_allocate(std::size_t bytes, std::size_t align) {
  void* memory = Runtime::get().allocate(bytes, align);
  pool_bytes_of_this_thread += bytes;
  return memory;
}

void pool_deallocate(void* ptr) noexcept {
  if (Runtime* runtime = Runtime::current()) runtime->deallocate(ptr);
}

}  // namespace agnocast::detail
