// How a message sits in the pool and how received entries are reference-counted.
// Internal to the library's templates; not part of the public API.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace agnocast::detail {

// What a service request or response carries besides its payload
// (service.hpp); zero in a topic's messages.
struct ServiceTag {
  // A request's number, unique per client, echoed by its response.
  std::uint64_t sequence = 0;
  // A request: the client's subscriber id on the reply topic, where its
  // response goes. A response: the server's publisher id on that topic.
  std::uint32_t peer = 0;
  // Which response to the request this is; always 0 (one response per request).
  std::uint16_t response_index = 0;
  std::uint16_t status = 0;  // ServiceStatus
};

enum class ServiceStatus : std::uint16_t {
  none = 0,  // not a service message
  request = 1,
  response = 2,
  // Sent to every client by a server that stops: what it has not answered never will be.
  server_gone = 3,
  // Sent to one client instead of a response: the server cannot answer this request.
  failed = 4,
};

// Placed right before every loaned message, in the publisher's own pool.
// Subscribers never write it; the publisher uses it to destroy the message
// when the kernel reports it reclaimable, even after the Publisher is gone.
struct MessageHeader {
  // The borrowing thread's heap scope (heap_scope.hpp) while the loan is
  // unpublished, else nullptr. First, so that the fields subscribers read
  // keep their distance from the message.
  void* heap_scope;
  void (*destroy)(void* message);
  void* block;  // the pool allocation that holds header and message
  // For the bandwidth counter: which thread borrowed the message and how many
  // pool bytes that thread had allocated by then.
  const std::uint64_t* borrowing_thread_counter;
  std::uint64_t pool_bytes_at_borrow;
  // Written at publish, read by subscribers for MessageInfo.
  std::int64_t publish_time;  // steady clock nanoseconds
  std::uint64_t published_bytes;
  ServiceTag service;
};

template <class T>
void destroy_message_object(void* message) {
  static_cast<T*>(message)->~T();
}

// Pool memory for a message of size/align, header filled; returns the message address.
void* allocate_message(std::size_t size, std::size_t align, void (*destroy)(void*));
// Opens a heap scope on the calling thread for the loan's lifetime (a message
// type that keeps its members on the heap); closed at publish or discard.
void open_loan_heap_scope(void* message);
// Closes the loan's heap scope, if it has one (from any thread).
void close_loan_heap_scope(void* message) noexcept;
// The message's size for the kernel's bandwidth counter: its own size plus
// what the publishing thread allocated from the pool since borrowing it (the
// vectors and strings filled in).  Just `size` when another thread borrowed it.
std::uint64_t published_bytes(void* message, std::size_t size) noexcept;
// Records publish time and size in the header, just before the message is published.
void stamp_publication(void* message, std::uint64_t bytes) noexcept;
// What a subscriber learns from the header of a received message; pool is the
// mapped pool holding it (publish_time and bytes stay 0 when the header lies outside).
struct Publication {
  std::int64_t publish_time = 0;
  std::uint64_t bytes = 0;
};
Publication read_publication(const void* message, const void* pool_begin,
                             std::size_t pool_size) noexcept;
// The pool mapped in this process that holds `address` (a publisher's, read-only,
// or this process's own), or an empty span: what a reader of a received
// message may read (ForeignMemory, <agnocast/schema_walk.hpp>).
std::span<const std::byte> pool_holding(const void* address);
// A loan's service tag, written before it is published.
void set_service_tag(void* message, const ServiceTag& tag) noexcept;
// The service tag of a received message, read from the pool that holds it;
// all zero when the header lies outside that pool.
ServiceTag read_service_tag(const void* message) noexcept;
// Frees memory from allocate_message whose object was never constructed.
void free_message_memory(void* message) noexcept;
// Destroys a constructed, unpublished message and frees its memory.
void discard_message(void* message) noexcept;

struct EntryReference;

// Whoever must hear that a received entry is no longer referenced (the
// subscriber), and takes the reference back for its next message.
class EntryOwner {
 public:
  virtual ~EntryOwner() = default;
  virtual void release_entry(std::uint64_t entry_id) noexcept = 0;
  virtual void recycle(EntryReference* reference) noexcept = 0;
};

// One received entry, shared by every ipc_shared_ptr copy that points to it.
struct EntryReference {
  std::atomic<std::uint32_t> count{1};
  std::shared_ptr<EntryOwner> owner;
  std::uint64_t entry_id = 0;
};

inline void retain(EntryReference* reference) noexcept {
  reference->count.fetch_add(1, std::memory_order_relaxed);
}
// The last release tells the owner and frees the reference.
void release(EntryReference* reference) noexcept;

}  // namespace agnocast::detail
