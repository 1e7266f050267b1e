#include "agnocast/log.hpp"

#include <memory>
#include <mutex>
#include <utility>

#include "log_internal.hpp"

namespace agnocast {
namespace {

std::mutex handler_mutex;
// Copied out under the lock so a handler may call set_log_handler itself.
std::shared_ptr<const LogHandler> installed_handler;

}  // namespace

void set_log_handler(LogHandler handler) {
  auto replacement = handler ? std::make_shared<const LogHandler>(std::move(handler)) : nullptr;
  std::lock_guard lock(handler_mutex);
  installed_handler = std::move(replacement);
}

namespace detail {

void log(LogLevel level, std::string_view message) noexcept {
  std::shared_ptr<const LogHandler> handler;
  {
    std::lock_guard lock(handler_mutex);
    handler = installed_handler;
  }
  if (!handler) return;
  try {
    (*handler)(level, message);
  } catch (...) {
    // A failing handler must not turn a warning into a crash of the caller.
  }
}

}  // namespace detail
}  // namespace agnocast
