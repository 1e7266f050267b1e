// Message types that keep std::vector / std::string members (declared with
// AGNOCAST_HEAP_MESSAGE) are shared in place when the program runs with the
// allocation hook, libagnocast_heaphook.so: inside a loan scope the calling
// thread's heap allocations come from its shared pool. borrow_loaned_message()
// opens a scope on the borrowing thread and publish() (or dropping the loan)
// closes it; heap_scope opens one explicitly, e.g. to fill members on a
// thread that did not borrow. Everything allocated outside a scope stays private.
#pragma once

#include <string_view>

namespace agnocast {

class heap_scope {
 public:
  // Opens a scope on this thread (setting up the process's pool first); does
  // nothing without the hook.
  heap_scope();
  ~heap_scope();
  heap_scope(const heap_scope&) = delete;
  heap_scope& operator=(const heap_scope&) = delete;

  // True when libagnocast_heaphook.so is this process's malloc.
  static bool hook_active() noexcept;

 private:
  void* token_;
};

namespace detail {

// The calling thread's scope token, or nullptr without the hook.
void* enter_heap_scope();
void leave_heap_scope(void* token) noexcept;
// Throws agnocast::Error, saying how to enable the hook, unless it is active.
void require_heap_hook(std::string_view type_name);

}  // namespace detail
}  // namespace agnocast
