// Two-level segregated fit allocator over one caller-provided region.
//
// Why TLSF: allocation and free are O(1) with bounded fragmentation, and all
// of its state but the free-list heads lives in the region, so it works on a
// pool at a fixed address. Not thread-safe; PoolAllocator adds the lock.
//
// Layout: every block is a 16-byte header {previous physical block, payload
// size | free bit} followed by its payload. A free block keeps its free-list
// links in its payload. A zero-size used sentinel header ends the region.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace agnocast::detail {

class Tlsf {
 public:
  static constexpr std::size_t alignment = 16;

  // region must be 16-byte aligned; the allocator owns it until destroyed.
  Tlsf(void* region, std::size_t size);
  Tlsf(const Tlsf&) = delete;
  Tlsf& operator=(const Tlsf&) = delete;

  // nullptr when no free block fits. align must be a power of two.
  void* allocate(std::size_t size, std::size_t align = alignment);
  // ptr must come from allocate() of this allocator (nullptr is ignored).
  void free(void* ptr);

  bool owns(const void* ptr) const;
  // Payload bytes usable at ptr (at least what was asked for).
  std::size_t usable_size(const void* ptr) const;

  struct Stats {
    std::size_t used_bytes = 0;  // payload of used blocks
    std::size_t free_bytes = 0;  // payload of free blocks
    std::size_t largest_free = 0;
    std::size_t used_blocks = 0;
    std::size_t free_blocks = 0;
  };
  // Walks every block and free list and checks the invariants (O(n), for tests).
  bool check(Stats* stats = nullptr) const;

 private:
  struct Block;
  static constexpr unsigned second_level_log2 = 5;
  static constexpr unsigned second_level_count = 1U << second_level_log2;
  // Sizes below this go to first level 0, split linearly in steps of alignment.
  static constexpr unsigned first_level_shift = second_level_log2 + 4;
  static constexpr std::size_t small_block_size = std::size_t{1} << first_level_shift;
  static constexpr unsigned first_level_count = 64 - first_level_shift + 1;

  struct Index {
    unsigned first;
    unsigned second;
  };
  static Index index_of(std::size_t size);
  static std::size_t round_up_for_search(std::size_t size);

  void insert_free(Block* block);
  void remove_free(Block* block);
  Block* find_free(std::size_t size);
  Block* find_in_own_class(std::size_t size);
  Block* split(Block* block, std::size_t size);
  Block* merge_with_neighbours(Block* block);

  char* begin_;
  char* end_;
  std::uint64_t first_level_map_ = 0;
  std::array<std::uint32_t, first_level_count> second_level_map_{};
  std::array<std::array<Block*, second_level_count>, first_level_count> heads_{};
};

}  // namespace agnocast::detail
