#include "own_pool.hpp"

#include <unistd.h>

#include <stdexcept>

#include "agnocast/inspect.hpp"

namespace agnocast_bridge {

void OwnPool::locate() {
  for (const auto& process : agnocast::list_processes()) {
    if (process.pid == ::getpid()) {
      begin_ = static_cast<std::uintptr_t>(process.pool_addr);
      size_ = static_cast<std::uintptr_t>(process.pool_size);
      return;
    }
  }
  throw std::runtime_error("the agnocast module does not list this process's pool");
}

}  // namespace agnocast_bridge
