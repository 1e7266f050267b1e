// libagnocast's side of the allocation hook (heaphook/heaphook_interface.h):
// found with dlsym when the process runs with it, never linked.
#pragma once

#include <cstddef>

namespace agnocast::detail {

// Hands the pool to the hook when there is one; called once the pool is mapped.
void attach_pool_to_heap_hook(void* begin, std::size_t size) noexcept;

}  // namespace agnocast::detail
