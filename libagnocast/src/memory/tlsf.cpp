#include "memory/tlsf.hpp"

#include <bit>
#include <cstring>

namespace agnocast::detail {

struct Tlsf::Block {
  Block* prev_phys;            // nullptr for the first block
  std::size_t size_and_flags;  // payload size (multiple of 16) | free bit
  // The payload starts here; free blocks keep their list links in it.
  Block* next_free;
  Block* prev_free;

  static constexpr std::size_t free_bit = 1;
  static constexpr std::size_t header_size = 2 * sizeof(void*);
  static constexpr std::size_t min_payload = 2 * sizeof(void*);

  std::size_t size() const { return size_and_flags & ~std::size_t{alignment - 1}; }
  bool is_free() const { return (size_and_flags & free_bit) != 0; }
  void set_size(std::size_t size) { size_and_flags = size | (size_and_flags & free_bit); }
  void set_free(bool free) { size_and_flags = size() | (free ? free_bit : 0); }
  char* payload() { return reinterpret_cast<char*>(this) + header_size; }
  Block* next_phys() { return reinterpret_cast<Block*>(payload() + size()); }
  static Block* from_payload(const void* payload) {
    return reinterpret_cast<Block*>(const_cast<char*>(static_cast<const char*>(payload)) -
                                    header_size);
  }
  static Block* at(char* address) { return reinterpret_cast<Block*>(address); }
};

static_assert(Tlsf::alignment == 2 * sizeof(void*), "one header is one alignment unit");

namespace {

constexpr std::size_t header_size = 2 * sizeof(void*);
constexpr std::size_t min_block = header_size + 2 * sizeof(void*);

std::uintptr_t align_up(std::uintptr_t value, std::size_t align) {
  return (value + align - 1) & ~std::uintptr_t(align - 1);
}

unsigned most_significant_bit(std::size_t value) {
  return 63U - static_cast<unsigned>(std::countl_zero(static_cast<std::uint64_t>(value)));
}

}  // namespace

Tlsf::Tlsf(void* region, std::size_t size) {
  const auto start = reinterpret_cast<std::uintptr_t>(region);
  const std::uintptr_t first = align_up(start, alignment);
  const std::uintptr_t last = (start + size) & ~std::uintptr_t(alignment - 1);
  begin_ = reinterpret_cast<char*>(first);
  end_ = reinterpret_cast<char*>(last > first ? last : first);
  if (static_cast<std::size_t>(end_ - begin_) < min_block + header_size) {
    end_ = begin_;  // too small to hold anything: every allocate() fails
    return;
  }
  Block* block = Block::at(begin_);
  block->prev_phys = nullptr;
  block->size_and_flags = static_cast<std::size_t>(end_ - begin_) - 2 * header_size;
  Block* sentinel = block->next_phys();
  sentinel->prev_phys = block;
  sentinel->size_and_flags = 0;
  insert_free(block);
}

Tlsf::Index Tlsf::index_of(std::size_t size) {
  if (size < small_block_size) {
    return {0, static_cast<unsigned>(size / (small_block_size / second_level_count))};
  }
  const unsigned msb = most_significant_bit(size);
  return {msb - first_level_shift + 1,
          static_cast<unsigned>(size >> (msb - second_level_log2)) ^ second_level_count};
}

// Rounds up to the next class boundary so that every block of the found class fits.
std::size_t Tlsf::round_up_for_search(std::size_t size) {
  if (size < small_block_size) return size;
  return size + (std::size_t{1} << (most_significant_bit(size) - second_level_log2)) - 1;
}

void Tlsf::insert_free(Block* block) {
  block->set_free(true);
  const Index index = index_of(block->size());
  Block*& head = heads_[index.first][index.second];
  block->prev_free = nullptr;
  block->next_free = head;
  if (head) head->prev_free = block;
  head = block;
  first_level_map_ |= std::uint64_t{1} << index.first;
  second_level_map_[index.first] |= 1U << index.second;
}

void Tlsf::remove_free(Block* block) {
  const Index index = index_of(block->size());
  if (block->prev_free) {
    block->prev_free->next_free = block->next_free;
  } else {
    heads_[index.first][index.second] = block->next_free;
  }
  if (block->next_free) block->next_free->prev_free = block->prev_free;
  if (!heads_[index.first][index.second]) {
    second_level_map_[index.first] &= ~(1U << index.second);
    if (!second_level_map_[index.first]) first_level_map_ &= ~(std::uint64_t{1} << index.first);
  }
  block->set_free(false);
}

Tlsf::Block* Tlsf::find_free(std::size_t size) {
  const Index index = index_of(round_up_for_search(size));
  if (index.first >= first_level_count) return nullptr;
  unsigned first = index.first;
  std::uint32_t second_map = second_level_map_[first] & (~0U << index.second);
  if (!second_map) {
    const std::uint64_t first_map =
        first + 1 < 64 ? first_level_map_ & (~std::uint64_t{0} << (first + 1)) : 0;
    if (!first_map) return find_in_own_class(size);
    first = static_cast<unsigned>(std::countr_zero(first_map));
    second_map = second_level_map_[first];
  }
  return heads_[first][static_cast<unsigned>(std::countr_zero(second_map))];
}

// Near exhaustion the rounded search misses blocks of size's own class that
// would fit; look through that one list before giving up.
Tlsf::Block* Tlsf::find_in_own_class(std::size_t size) {
  const Index index = index_of(size);
  for (Block* block = heads_[index.first][index.second]; block; block = block->next_free) {
    if (block->size() >= size) return block;
  }
  return nullptr;
}

// Cuts block (used, not in a list) to size and frees the tail if it can stand alone.
Tlsf::Block* Tlsf::split(Block* block, std::size_t size) {
  const std::size_t size_before = block->size();
  if (size_before - size < min_block) return block;
  Block* rest = Block::at(block->payload() + size);
  rest->size_and_flags = size_before - size - header_size;
  rest->prev_phys = block;
  block->set_size(size);
  // block was free, so the block after it is used: rest needs no merging.
  rest->next_phys()->prev_phys = rest;
  insert_free(rest);
  return block;
}

Tlsf::Block* Tlsf::merge_with_neighbours(Block* block) {
  if (Block* previous = block->prev_phys; previous && previous->is_free()) {
    remove_free(previous);
    previous->set_size(previous->size() + header_size + block->size());
    block = previous;
    block->next_phys()->prev_phys = block;
  }
  if (Block* next = block->next_phys(); next->is_free()) {
    remove_free(next);
    block->set_size(block->size() + header_size + next->size());
    block->next_phys()->prev_phys = block;
  }
  return block;
}

void* Tlsf::allocate(std::size_t size, std::size_t align) {
  if (align == 0 || (align & (align - 1)) != 0) return nullptr;
  const std::size_t capacity = static_cast<std::size_t>(end_ - begin_);
  if (size > capacity || align > capacity) return nullptr;
  size = size < Block::min_payload ? Block::min_payload : align_up(size, alignment);

  if (align <= alignment) {
    Block* block = find_free(size);
    if (!block) return nullptr;
    remove_free(block);
    return split(block, size)->payload();
  }

  // Over-aligned: find room for the alignment gap, then free the gap as its own block.
  Block* block = find_free(size + align + min_block);
  if (!block) return nullptr;
  remove_free(block);
  const auto payload = reinterpret_cast<std::uintptr_t>(block->payload());
  std::uintptr_t aligned = align_up(payload, align);
  if (aligned != payload && aligned - payload < min_block)
    aligned = align_up(payload + min_block, align);
  if (aligned != payload) {
    const std::size_t gap = aligned - payload;
    Block* moved = Block::from_payload(reinterpret_cast<void*>(aligned));
    moved->prev_phys = block;
    moved->size_and_flags = block->size() - gap;
    moved->next_phys()->prev_phys = moved;
    block->set_size(gap - header_size);
    insert_free(block);  // its previous block is used: it was free before
    block = moved;
  }
  return split(block, size)->payload();
}

void Tlsf::free(void* ptr) {
  if (!ptr) return;
  insert_free(merge_with_neighbours(Block::from_payload(ptr)));
}

bool Tlsf::owns(const void* ptr) const {
  const char* p = static_cast<const char*>(ptr);
  return p >= begin_ + header_size && p < end_;
}

std::size_t Tlsf::usable_size(const void* ptr) const { return Block::from_payload(ptr)->size(); }

bool Tlsf::check(Stats* stats) const {
  Stats found;
  if (begin_ == end_) {
    if (stats) *stats = found;
    return first_level_map_ == 0;
  }
  Block* previous = nullptr;
  Block* block = Block::at(begin_);
  while (block->size() != 0) {
    if (block->prev_phys != previous) return false;
    if (block->is_free()) {
      if (previous && previous->is_free()) return false;  // free neighbours must be merged
      found.free_bytes += block->size();
      found.largest_free = std::max(found.largest_free, block->size());
      ++found.free_blocks;
    } else {
      found.used_bytes += block->size();
      ++found.used_blocks;
    }
    if (block->size() % alignment != 0) return false;
    previous = block;
    block = block->next_phys();
    if (reinterpret_cast<char*>(block) >= end_) return false;
  }
  if (block->prev_phys != previous || reinterpret_cast<char*>(block) != end_ - header_size) {
    return false;
  }
  std::size_t listed = 0;
  for (unsigned first = 0; first < first_level_count; ++first) {
    for (unsigned second = 0; second < second_level_count; ++second) {
      const bool marked =
          ((first_level_map_ >> first) & 1U) && ((second_level_map_[first] >> second) & 1U);
      Block* head = heads_[first][second];
      if (marked != (head != nullptr)) return false;
      Block* before = nullptr;
      for (Block* free = head; free; free = free->next_free) {
        const Index index = index_of(free->size());
        if (!free->is_free() || free->prev_free != before || index.first != first ||
            index.second != second) {
          return false;
        }
        before = free;
        ++listed;
      }
    }
  }
  if (listed != found.free_blocks) return false;
  if (stats) *stats = found;
  return true;
}

}  // namespace agnocast::detail
