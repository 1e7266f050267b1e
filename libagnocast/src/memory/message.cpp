// The message header placed before every loaned message (detail/message.hpp)
// and the reference counting of received entries.
#include "agnocast/detail/message.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <utility>

#include "agnocast/allocator.hpp"
#include "agnocast/heap_scope.hpp"
#include "kernel/runtime.hpp"
#include "memory/tlsf.hpp"
#include "tracing/trace.hpp"

namespace agnocast::detail {
namespace {

constexpr std::size_t header_room = sizeof(MessageHeader);
static_assert(header_room % alignof(MessageHeader) == 0);

MessageHeader* header_of(void* message) {
  return reinterpret_cast<MessageHeader*>(static_cast<char*>(message) - header_room);
}

}  // namespace

void* allocate_message(std::size_t size, std::size_t align, void (*destroy)(void*)) {
  align = std::max(align, Tlsf::alignment);
  const std::size_t offset = (header_room + align - 1) & ~(align - 1);  // keeps message aligned
  Runtime& runtime = Runtime::get();
  runtime.free_deferred();  // what the last publish reclaimed
  void* block = runtime.allocate(offset + size, align);
  void* message = static_cast<char*>(block) + offset;
  const std::uint64_t& thread_counter = pool_bytes_allocated_by_this_thread();
  *header_of(message) =
      MessageHeader{nullptr, destroy, block, &thread_counter, thread_counter, 0, 0, ServiceTag{}};
  AGNOCAST_TRACE(agnocast_loan, message, static_cast<std::uint64_t>(size));
  return message;
}

void open_loan_heap_scope(void* message) { header_of(message)->heap_scope = enter_heap_scope(); }

void close_loan_heap_scope(void* message) noexcept {
  leave_heap_scope(std::exchange(header_of(message)->heap_scope, nullptr));
}

std::uint64_t published_bytes(void* message, std::size_t size) noexcept {
  const MessageHeader& header = *header_of(message);
  const std::uint64_t& thread_counter = pool_bytes_allocated_by_this_thread();
  if (header.borrowing_thread_counter != &thread_counter) return size;
  return size + (thread_counter - header.pool_bytes_at_borrow);
}

void stamp_publication(void* message, std::uint64_t bytes) noexcept {
  MessageHeader& header = *header_of(message);
  header.publish_time = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::steady_clock::now().time_since_epoch())
                            .count();
  header.published_bytes = bytes;
}

std::span<const std::byte> pool_holding(const void* address) {
  return Runtime::get().pool_holding(address);
}

Publication read_publication(const void* message, const void* pool_begin,
                             std::size_t pool_size) noexcept {
  const auto at = reinterpret_cast<std::uintptr_t>(message);
  const auto begin = reinterpret_cast<std::uintptr_t>(pool_begin);
  // Another process wrote the address: only trust a header inside its pool.
  if (at < begin + header_room || at - begin > pool_size) return {};
  const auto* header =
      reinterpret_cast<const MessageHeader*>(static_cast<const char*>(message) - header_room);
  return Publication{header->publish_time, header->published_bytes};
}

void set_service_tag(void* message, const ServiceTag& tag) noexcept {
  header_of(message)->service = tag;
}

ServiceTag read_service_tag(const void* message) noexcept {
  const std::span<const std::byte> pool = pool_holding(message);
  const auto at = reinterpret_cast<std::uintptr_t>(message);
  const auto begin = reinterpret_cast<std::uintptr_t>(pool.data());
  // Another process wrote the address: only trust a header inside its pool.
  if (pool.empty() || at < begin + header_room || at - begin > pool.size()) return {};
  const auto* header =
      reinterpret_cast<const MessageHeader*>(static_cast<const char*>(message) - header_room);
  return header->service;
}

void free_message_memory(void* message) noexcept {
  close_loan_heap_scope(message);
  pool_deallocate(header_of(message)->block);
}

void discard_message(void* message) noexcept {
  close_loan_heap_scope(message);
  const MessageHeader header = *header_of(message);
  header.destroy(message);
  pool_deallocate(header.block);
}

void release(EntryReference* reference) noexcept {
  if (reference->count.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
  // The reference may hold the owner's last pointer: keep it alive until the
  // reference is handed back.
  const std::shared_ptr<EntryOwner> owner = std::move(reference->owner);
  owner->release_entry(reference->entry_id);
  owner->recycle(reference);
}

}  // namespace agnocast::detail
