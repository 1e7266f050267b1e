#include "memory/tlsf.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <vector>

namespace agnocast::detail {
namespace {

struct Region {
  explicit Region(std::size_t size)
      : bytes(new (std::align_val_t{64}) std::byte[size]), size(size) {}
  ~Region() { ::operator delete[](bytes, std::align_val_t{64}); }
  std::byte* bytes;
  std::size_t size;
};

constexpr std::size_t overhead = 2 * Tlsf::alignment;  // first header + sentinel

TEST(Tlsf, FreshRegionIsOneFreeBlock) {
  Region region(1 << 20);
  Tlsf tlsf(region.bytes, region.size);
  Tlsf::Stats stats;
  ASSERT_TRUE(tlsf.check(&stats));
  EXPECT_EQ(stats.free_blocks, 1U);
  EXPECT_EQ(stats.free_bytes, region.size - overhead);
  EXPECT_EQ(stats.used_blocks, 0U);
}

TEST(Tlsf, FreeingEverythingCoalescesBackToOneBlock) {
  Region region(1 << 20);
  Tlsf tlsf(region.bytes, region.size);
  std::vector<void*> blocks;
  for (int i = 0; i < 100; ++i) blocks.push_back(tlsf.allocate(100 + i * 7));
  // Free every other block first so that later frees merge on both sides.
  for (std::size_t i = 0; i < blocks.size(); i += 2) tlsf.free(blocks[i]);
  ASSERT_TRUE(tlsf.check());
  for (std::size_t i = 1; i < blocks.size(); i += 2) tlsf.free(blocks[i]);
  Tlsf::Stats stats;
  ASSERT_TRUE(tlsf.check(&stats));
  EXPECT_EQ(stats.free_blocks, 1U);
  EXPECT_EQ(stats.free_bytes, region.size - overhead);
}

TEST(Tlsf, HonoursEveryPowerOfTwoAlignment) {
  Region region(4 << 20);
  Tlsf tlsf(region.bytes, region.size);
  std::vector<void*> blocks;
  for (std::size_t align = 1; align <= 65536; align *= 2) {
    for (std::size_t size : {1UL, 15UL, 16UL, 17UL, 1000UL}) {
      void* p = tlsf.allocate(size, align);
      ASSERT_NE(p, nullptr) << size << " @ " << align;
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % std::max(align, Tlsf::alignment), 0U);
      EXPECT_GE(tlsf.usable_size(p), size);
      std::memset(p, 0xAB, size);
      blocks.push_back(p);
      ASSERT_TRUE(tlsf.check());
    }
  }
  for (void* p : blocks) tlsf.free(p);
  Tlsf::Stats stats;
  ASSERT_TRUE(tlsf.check(&stats));
  EXPECT_EQ(stats.free_blocks, 1U);
}

TEST(Tlsf, RejectsBadAlignmentAndOversizedRequests) {
  Region region(1 << 16);
  Tlsf tlsf(region.bytes, region.size);
  EXPECT_EQ(tlsf.allocate(16, 3), nullptr);
  EXPECT_EQ(tlsf.allocate(16, 0), nullptr);
  EXPECT_EQ(tlsf.allocate(region.size), nullptr);
  EXPECT_EQ(tlsf.allocate(SIZE_MAX), nullptr);
  EXPECT_EQ(tlsf.allocate(SIZE_MAX - 8), nullptr);
  EXPECT_NE(tlsf.allocate(region.size - overhead), nullptr);  // exactly the whole region fits
  EXPECT_TRUE(tlsf.check());
}

TEST(Tlsf, TinyRegionAllocatesNothing) {
  Region region(32);
  Tlsf tlsf(region.bytes, region.size);
  EXPECT_EQ(tlsf.allocate(1), nullptr);
  EXPECT_TRUE(tlsf.check());
}

TEST(Tlsf, ExhaustionRecoversAfterFree) {
  Region region(1 << 20);
  Tlsf tlsf(region.bytes, region.size);
  std::vector<void*> blocks;
  while (void* p = tlsf.allocate(4096)) blocks.push_back(p);
  EXPECT_GT(blocks.size(), 200U);
  EXPECT_EQ(tlsf.allocate(4096), nullptr);
  tlsf.free(blocks[blocks.size() / 2]);
  EXPECT_NE(tlsf.allocate(4096), nullptr);
  EXPECT_TRUE(tlsf.check());
}

TEST(Tlsf, OwnsOnlyItsRegion) {
  Region region(1 << 16);
  Tlsf tlsf(region.bytes, region.size);
  void* p = tlsf.allocate(10);
  int outside = 0;
  EXPECT_TRUE(tlsf.owns(p));
  EXPECT_FALSE(tlsf.owns(&outside));
}

// Random allocate/free against a model: contents survive, blocks never overlap,
// and the invariants hold throughout.
TEST(Tlsf, RandomOperationsMatchAModel) {
  Region region(8 << 20);
  Tlsf tlsf(region.bytes, region.size);
  std::mt19937_64 random(42);
  struct Live {
    std::size_t size;
    unsigned char fill;
  };
  std::map<char*, Live> live;
  auto random_size = [&] {
    switch (random() % 10) {
      case 0:
        return static_cast<std::size_t>(random() % (512 << 10));
      case 1:
        return static_cast<std::size_t>(random() % 16);
      default:
        return static_cast<std::size_t>(random() % 4096);
    }
  };
  std::size_t failures = 0;
  for (int step = 0; step < 40000; ++step) {
    if (live.empty() || random() % 100 < 55) {
      const std::size_t size = random_size();
      const std::size_t align = std::size_t{1} << (random() % 4 == 0 ? random() % 13 : 0);
      char* p = static_cast<char*>(tlsf.allocate(size, align));
      if (!p) {
        ++failures;
        continue;
      }
      ASSERT_EQ(reinterpret_cast<std::uintptr_t>(p) % std::max(align, Tlsf::alignment), 0U);
      auto next = live.lower_bound(p);
      if (next != live.end()) {
        ASSERT_LE(p + size, next->first) << "overlaps the next block";
      }
      if (next != live.begin()) {
        auto previous = std::prev(next);
        ASSERT_LE(previous->first + previous->second.size, p) << "overlaps the previous block";
      }
      const auto fill = static_cast<unsigned char>(random());
      std::memset(p, fill, size);
      live[p] = {size, fill};
    } else {
      auto it = live.begin();
      std::advance(it, static_cast<long>(random() % live.size()));
      for (std::size_t i = 0; i < it->second.size; ++i) {
        ASSERT_EQ(static_cast<unsigned char>(it->first[i]), it->second.fill) << "corrupted";
      }
      tlsf.free(it->first);
      live.erase(it);
    }
    if (step % 1000 == 0) {
      ASSERT_TRUE(tlsf.check()) << "step " << step;
    }
  }
  for (auto& [p, block] : live) tlsf.free(p);
  Tlsf::Stats stats;
  ASSERT_TRUE(tlsf.check(&stats));
  EXPECT_EQ(stats.free_blocks, 1U);
  EXPECT_EQ(stats.free_bytes, region.size - overhead);
  RecordProperty("allocation_failures", static_cast<int>(failures));
}

TEST(Tlsf, FreedSpaceIsFoundAgainForTheSameSize) {
  Region region(1 << 20);
  Tlsf tlsf(region.bytes, region.size);
  for (std::size_t size = 1; size < 300000; size = size * 3 + 1) {
    void* a = tlsf.allocate(size);
    ASSERT_NE(a, nullptr);
    void* b = tlsf.allocate(size);
    tlsf.free(a);
    void* c = tlsf.allocate(size);
    EXPECT_NE(c, nullptr);
    tlsf.free(b);
    tlsf.free(c);
    ASSERT_TRUE(tlsf.check());
  }
}

}  // namespace
}  // namespace agnocast::detail
