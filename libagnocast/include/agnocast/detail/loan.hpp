// Borrowing a message from this process's pool and handing it back: one way
// for publishers, servers and clients alike.
#pragma once

#include <new>
#include <stdexcept>
#include <string>

#include "agnocast/detail/message.hpp"
#include "agnocast/heap_scope.hpp"
#include "agnocast/ipc_shared_ptr.hpp"
#include "agnocast/message_traits.hpp"

namespace agnocast::detail {

// A default-constructed T in this process's shared pool. For a heap message
// (AGNOCAST_HEAP_MESSAGE), this thread allocates in the pool until the loan
// is sent or dropped (heap_scope.hpp).
template <class T>
T* borrow_loan() {
  void* memory = allocate_message(sizeof(T), alignof(T), &destroy_message_object<T>);
  try {
    if constexpr (HeapMessage<T>) open_loan_heap_scope(memory);
    return new (memory) T();
  } catch (...) {
    free_message_memory(memory);
    throw;
  }
}

// Takes the message out of a loan to send it; rule is what the caller must
// pass (std::invalid_argument when the pointer is empty or not a loan).
template <class T>
T* loan_to_send(ipc_shared_ptr<T>& loan, const char* rule) {
  T* loaned = MessageAccess::release_loan(loan);
  if (!loaned) throw std::invalid_argument(std::string("agnocast: ") + rule);
  return loaned;
}

}  // namespace agnocast::detail
