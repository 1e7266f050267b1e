#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "agnocast/detail/message.hpp"

namespace agnocast {

template <class T>
class Publisher;
namespace detail {
struct MessageAccess;
}

// A message in shared memory.
// Publisher side (ipc_shared_ptr<T>): a loan from borrow_loaned_message(),
// move-only, handed back by publish(); dropping an unpublished loan frees it.
// Subscriber side (ipc_shared_ptr<const T>): copyable; the last copy releases
// the kernel's reference so the publisher may reuse the memory.
template <class T>
class ipc_shared_ptr {
 public:
  ipc_shared_ptr() noexcept = default;
  ipc_shared_ptr(std::nullptr_t) noexcept {}
  ~ipc_shared_ptr() { reset(); }

  ipc_shared_ptr(ipc_shared_ptr&& other) noexcept
      : ptr_(std::exchange(other.ptr_, nullptr)),
        reference_(std::exchange(other.reference_, nullptr)) {}
  ipc_shared_ptr& operator=(ipc_shared_ptr&& other) noexcept {
    if (this != &other) {
      reset();
      ptr_ = std::exchange(other.ptr_, nullptr);
      reference_ = std::exchange(other.reference_, nullptr);
    }
    return *this;
  }

  ipc_shared_ptr(const ipc_shared_ptr& other) noexcept requires std::is_const_v<T>
      : ptr_(other.ptr_), reference_(other.reference_) {
    if (reference_) detail::retain(reference_);
  }
  ipc_shared_ptr& operator=(const ipc_shared_ptr& other) noexcept requires std::is_const_v<T> {
    if (this != &other) {
      if (other.reference_) detail::retain(other.reference_);
      reset();
      ptr_ = other.ptr_;
      reference_ = other.reference_;
    }
    return *this;
  }

  T* get() const noexcept { return ptr_; }
  T& operator*() const noexcept { return *ptr_; }
  T* operator->() const noexcept { return ptr_; }
  explicit operator bool() const noexcept { return ptr_ != nullptr; }

  // The kernel's id of a received entry (0 for a loan or an empty pointer).
  std::uint64_t entry_id() const noexcept { return reference_ ? reference_->entry_id : 0; }
  // How many ipc_shared_ptr copies share this received entry (0 for a loan).
  std::uint32_t use_count() const noexcept {
    return reference_ ? reference_->count.load(std::memory_order_relaxed) : 0;
  }

  void reset() noexcept {
    if (reference_) {
      detail::release(std::exchange(reference_, nullptr));
    } else if (ptr_) {
      detail::discard_message(const_cast<std::remove_const_t<T>*>(ptr_));
    }
    ptr_ = nullptr;
  }

 private:
  friend struct detail::MessageAccess;
  template <class>
  friend class Publisher;

  ipc_shared_ptr(T* ptr, detail::EntryReference* reference) noexcept
      : ptr_(ptr), reference_(reference) {}

  T* ptr_ = nullptr;
  detail::EntryReference* reference_ = nullptr;  // null on the publisher side
};

namespace detail {

// Lets the library's templates build and dismantle pointers.
struct MessageAccess {
  template <class T>
  static ipc_shared_ptr<T> loan(T* message) noexcept {
    return ipc_shared_ptr<T>(message, nullptr);
  }
  template <class T>
  static ipc_shared_ptr<const T> received(const T* message, EntryReference* reference) noexcept {
    return ipc_shared_ptr<const T>(message, reference);
  }
  // Takes the message out of a loan; nullptr if it is empty or not a loan.
  template <class T>
  static T* release_loan(ipc_shared_ptr<T>& loan) noexcept {
    if (loan.reference_) return nullptr;
    return std::exchange(loan.ptr_, nullptr);
  }
};

}  // namespace detail
}  // namespace agnocast
