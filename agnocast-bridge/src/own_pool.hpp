// The bridge's own agnocast pool: every message in it was published by the
// bridge itself (the pool is writable by this process only), so a to_dds
// subscription skips it instead of sending a from_dds message back to DDS.
#pragma once

#include <cstdint>

namespace agnocast_bridge {

class OwnPool {
 public:
  // Reads this process's pool address and size from the kernel; call after
  // the first agnocast endpoint was created.
  void locate();
  bool holds(const void* address) const {
    const auto at = reinterpret_cast<std::uintptr_t>(address);
    return at >= begin_ && at - begin_ < size_;
  }

 private:
  std::uintptr_t begin_ = 0;
  std::uintptr_t size_ = 0;
};

}  // namespace agnocast_bridge
