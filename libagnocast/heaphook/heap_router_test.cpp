// The hook's routing, driven with a fake pool (a Tlsf over a buffer here) and
// a counting stand-in for glibc.
#include "heap_router.hpp"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "memory/tlsf.hpp"

namespace agnocast::heaphook {
namespace {

struct Counts {
  std::atomic<int> malloc{0}, free{0}, calloc{0}, realloc{0}, memalign{0}, usable{0};
};
Counts system_counts;
std::vector<std::string> reports;

void* system_malloc(std::size_t size) {
  ++system_counts.malloc;
  return std::malloc(size);
}
void system_free(void* ptr) {
  ++system_counts.free;
  std::free(ptr);
}
void* system_calloc(std::size_t count, std::size_t size) {
  ++system_counts.calloc;
  return std::calloc(count, size);
}
void* system_realloc(void* ptr, std::size_t size) {
  ++system_counts.realloc;
  return std::realloc(ptr, size);
}
void* system_memalign(std::size_t align, std::size_t size) {
  ++system_counts.memalign;
  return std::aligned_alloc(align, (size + align - 1) / align * align);
}
std::size_t system_usable(void* ptr) {
  ++system_counts.usable;
  return ::malloc_usable_size(ptr);
}
void record_report(const char* line, std::size_t length) { reports.emplace_back(line, length); }

constexpr SystemHeap fake_system{system_malloc,   system_free,   system_calloc, system_realloc,
                                 system_memalign, system_usable, record_report};

// The fake pool: what libagnocast's pool functions do, over a test buffer.
struct FakePool {
  static constexpr std::size_t size = 1 << 20;
  alignas(4096) static inline std::byte region[size];
  static inline std::mutex mutex;
  static inline detail::Tlsf* tlsf = nullptr;
  static inline std::atomic<int> allocations{0}, frees{0};
  // Set by a test: what the pool itself allocates while it runs (a reclaim round does).
  static inline HeapRouter* reentered_by = nullptr;

  static void* allocate(std::size_t bytes, std::size_t align) {
    if (reentered_by) reentered_by->free(reentered_by->malloc(32));
    std::lock_guard lock(mutex);
    ++allocations;
    return tlsf->allocate(bytes, align);
  }
  static void deallocate(void* ptr) {
    std::lock_guard lock(mutex);
    ++frees;
    tlsf->free(ptr);
  }
  static std::size_t usable_size(const void* ptr) {
    std::lock_guard lock(mutex);
    return tlsf->usable_size(ptr);
  }
  static agnocast_heaphook_pool description() {
    return {reinterpret_cast<std::uintptr_t>(region), size, allocate, deallocate, usable_size};
  }
};

class HeapRouterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    alignas(detail::Tlsf) static std::byte storage[sizeof(detail::Tlsf)];
    FakePool::tlsf = new (storage) detail::Tlsf(FakePool::region, FakePool::size);
    FakePool::allocations = 0;
    FakePool::frees = 0;
    FakePool::reentered_by = nullptr;
    system_counts.malloc = system_counts.free = system_counts.calloc = 0;
    system_counts.realloc = system_counts.memalign = system_counts.usable = 0;
    reports.clear();
    HeapRouter::reset_thread();
    router.attach_pool(FakePool::description());
  }
  void TearDown() override { HeapRouter::reset_thread(); }

  HeapRouter router{fake_system};
};

struct Scope {
  Scope() : token(HeapRouter::enter_scope()) {}
  ~Scope() { HeapRouter::leave_scope(token); }
  void* token;
};

TEST_F(HeapRouterTest, OutsideAScopeEverythingGoesToTheSystem) {
  void* ptr = router.malloc(100);
  void* zeroed = router.calloc(10, 10);
  void* aligned = router.memalign(64, 100);
  EXPECT_FALSE(router.in_pool(ptr));
  EXPECT_FALSE(router.in_pool(zeroed));
  EXPECT_FALSE(router.in_pool(aligned));
  EXPECT_EQ(FakePool::allocations, 0);
  EXPECT_EQ(system_counts.malloc, 1);
  EXPECT_EQ(system_counts.calloc, 1);
  EXPECT_EQ(system_counts.memalign, 1);
  router.free(ptr);
  router.free(zeroed);
  router.free(aligned);
  EXPECT_EQ(system_counts.free, 3);
}

TEST_F(HeapRouterTest, InsideAScopeEveryKindOfAllocationComesFromThePool) {
  Scope scope;
  void* plain = router.malloc(100);
  void* empty = router.malloc(0);
  void* aligned = router.memalign(256, 10);
  void* odd_alignment = router.memalign(48, 10);  // rounded up to 64, as glibc does
  void* posix = nullptr;
  ASSERT_EQ(router.posix_memalign(&posix, 4096, 5000), 0);
  for (void* ptr : {plain, empty, aligned, odd_alignment, posix}) {
    ASSERT_NE(ptr, nullptr);
    EXPECT_TRUE(router.in_pool(ptr));
  }
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(plain) % 16, 0U);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(aligned) % 256, 0U);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(odd_alignment) % 64, 0U);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(posix) % 4096, 0U);
  EXPECT_NE(plain, empty);
  EXPECT_EQ(FakePool::allocations, 5);
  EXPECT_EQ(system_counts.malloc + system_counts.memalign, 0);
  for (void* ptr : {plain, empty, aligned, odd_alignment, posix}) router.free(ptr);
  EXPECT_EQ(FakePool::frees, 5);
  EXPECT_EQ(system_counts.free, 0);
}

TEST_F(HeapRouterTest, CallocFromThePoolIsZeroedEvenOverReusedMemory) {
  Scope scope;
  void* dirty = router.malloc(4096);
  std::memset(dirty, 0xAB, 4096);
  router.free(dirty);
  auto* zeroed = static_cast<unsigned char*>(router.calloc(64, 64));
  ASSERT_TRUE(router.in_pool(zeroed));
  for (int i = 0; i < 4096; ++i) ASSERT_EQ(zeroed[i], 0) << i;
  router.free(zeroed);
  errno = 0;
  EXPECT_EQ(router.calloc(SIZE_MAX / 2, 3), nullptr);
  EXPECT_EQ(errno, ENOMEM);
}

TEST_F(HeapRouterTest, FreeGoesToTheOwnerByAddressWhateverTheScope) {
  void* private_block = router.malloc(64);
  void* pool_block;
  {
    Scope scope;
    pool_block = router.malloc(64);
    router.free(private_block);  // inside the scope, still glibc's
  }
  EXPECT_EQ(system_counts.free, 1);
  EXPECT_EQ(FakePool::frees, 0);
  router.free(pool_block);  // outside the scope, still the pool's
  EXPECT_EQ(FakePool::frees, 1);
  EXPECT_EQ(system_counts.free, 1);
  router.free(nullptr);
  EXPECT_EQ(system_counts.free, 1);
}

TEST_F(HeapRouterTest, ReallocMovesABlockToWhereMallocWouldPutItNow) {
  auto* private_block = static_cast<char*>(router.malloc(100));
  std::memcpy(private_block, "private bytes", 14);
  char* pooled;
  {
    Scope scope;
    pooled = static_cast<char*>(router.realloc(private_block, 10000));  // grows into the pool
    ASSERT_TRUE(router.in_pool(pooled));
    EXPECT_STREQ(pooled, "private bytes");
    EXPECT_EQ(system_counts.free, 1);                                  // the private block is gone
    char* grown = static_cast<char*>(router.realloc(pooled, 100000));  // pool to pool
    ASSERT_TRUE(router.in_pool(grown));
    EXPECT_STREQ(grown, "private bytes");
    char* shrunk = static_cast<char*>(router.realloc(grown, 20));
    ASSERT_TRUE(router.in_pool(shrunk));
    EXPECT_STREQ(shrunk, "private bytes");
    pooled = shrunk;
  }
  const int pool_frees = FakePool::frees;
  char* back = static_cast<char*>(router.realloc(pooled, 50));  // out of the pool again
  ASSERT_FALSE(router.in_pool(back));
  EXPECT_STREQ(back, "private bytes");
  EXPECT_EQ(FakePool::frees, pool_frees + 1);
  EXPECT_EQ(system_counts.realloc, 0);                           // glibc never saw a pool pointer
  char* plain = static_cast<char*>(router.realloc(back, 5000));  // glibc's own business
  EXPECT_EQ(system_counts.realloc, 1);
  EXPECT_STREQ(plain, "private bytes");
  router.free(plain);
}

TEST_F(HeapRouterTest, ReallocToZeroAndFromNullFollowGlibc) {
  Scope scope;
  void* block = router.realloc(nullptr, 40);
  ASSERT_TRUE(router.in_pool(block));
  EXPECT_EQ(router.realloc(block, 0), nullptr);
  EXPECT_EQ(FakePool::frees, 1);
}

TEST_F(HeapRouterTest, UsableSizeAsksTheOwner) {
  void* private_block = router.malloc(100);
  EXPECT_GE(router.usable_size(private_block), 100U);
  EXPECT_EQ(system_counts.usable, 1);
  {
    Scope scope;
    void* pool_block = router.malloc(100);
    EXPECT_GE(router.usable_size(pool_block), 100U);
    EXPECT_EQ(router.usable_size(pool_block), FakePool::usable_size(pool_block));
    EXPECT_EQ(system_counts.usable, 1);
    router.free(pool_block);
  }
  EXPECT_EQ(router.usable_size(nullptr), 0U);
  router.free(private_block);
}

TEST_F(HeapRouterTest, PosixMemalignRefusesBadAlignmentsWithoutTouchingTheOutput) {
  Scope scope;
  void* out = &out;
  EXPECT_EQ(router.posix_memalign(&out, 24, 10), EINVAL);
  EXPECT_EQ(router.posix_memalign(&out, 4, 10), EINVAL);  // below sizeof(void*)
  EXPECT_EQ(out, &out);
  EXPECT_EQ(FakePool::allocations, 0);
}

TEST_F(HeapRouterTest, AFullPoolFailsLikeMallocAndSaysSoOnce) {
  Scope scope;
  errno = 0;
  EXPECT_EQ(router.malloc(2 * FakePool::size), nullptr);
  EXPECT_EQ(errno, ENOMEM);
  void* out = nullptr;
  EXPECT_EQ(router.posix_memalign(&out, 64, 2 * FakePool::size), ENOMEM);
  void* kept = router.malloc(16);
  std::memcpy(kept, "kept", 5);
  EXPECT_EQ(router.realloc(kept, 2 * FakePool::size), nullptr);
  EXPECT_STREQ(static_cast<char*>(kept), "kept");  // realloc failing leaves it valid
  router.free(kept);
  ASSERT_EQ(reports.size(), 1U);
  EXPECT_NE(reports[0].find("has no room for 2097152 bytes"), std::string::npos) << reports[0];
  EXPECT_NE(reports[0].find("pool_size"), std::string::npos) << reports[0];
  EXPECT_EQ(system_counts.malloc, 0);  // never falls back to private memory
}

TEST_F(HeapRouterTest, WhatThePoolAllocatesForItselfIsNotRouted) {
  FakePool::reentered_by = &router;
  Scope scope;
  void* block = router.malloc(100);
  EXPECT_TRUE(router.in_pool(block));
  EXPECT_EQ(FakePool::allocations, 1);
  EXPECT_EQ(system_counts.malloc, 1);  // the pool's own allocation
  router.free(block);
}

TEST_F(HeapRouterTest, ScopesNestAndEndWithTheirLastToken) {
  void* outer = HeapRouter::enter_scope();
  void* inner = HeapRouter::enter_scope();
  HeapRouter::leave_scope(inner);
  EXPECT_TRUE(HeapRouter::in_scope());
  HeapRouter::leave_scope(outer);
  EXPECT_FALSE(HeapRouter::in_scope());
}

TEST_F(HeapRouterTest, WithoutAPoolAScopeStillAllocatesPrivately) {
  HeapRouter unattached{fake_system};
  Scope scope;
  void* block = unattached.malloc(10);
  EXPECT_FALSE(unattached.in_pool(block));
  EXPECT_EQ(system_counts.malloc, 1);
  unattached.free(block);
}

TEST_F(HeapRouterTest, AForkChildForgetsThePoolAndItsScopes) {
  void* token = HeapRouter::enter_scope();
  void* inherited = router.malloc(100);
  ASSERT_TRUE(router.in_pool(inherited));
  router.retire_pool();  // what the fork handler runs in the child
  EXPECT_FALSE(HeapRouter::in_scope());
  router.free(inherited);  // the parent's pool: not ours to free, and not glibc's
  EXPECT_EQ(FakePool::frees, 0);
  EXPECT_EQ(system_counts.free, 0);
  EXPECT_EQ(router.usable_size(inherited), 0U);
  (void)token;
  HeapRouter::enter_scope();
  void* fresh = router.malloc(100);
  EXPECT_FALSE(router.in_pool(fresh));
  router.free(fresh);
}

TEST_F(HeapRouterTest, ScopesBelongToThreads) {
  constexpr int rounds = 2000;
  std::vector<void*> inside(rounds), outside(rounds);
  std::thread scoped([&] {
    Scope scope;
    for (int i = 0; i < rounds; ++i) inside[i] = router.malloc(16 + i % 200);
  });
  std::thread plain([&] {
    for (int i = 0; i < rounds; ++i) outside[i] = router.malloc(16 + i % 200);
  });
  scoped.join();
  plain.join();
  EXPECT_FALSE(HeapRouter::in_scope());
  for (int i = 0; i < rounds; ++i) {
    ASSERT_TRUE(router.in_pool(inside[i])) << i;
    ASSERT_FALSE(router.in_pool(outside[i])) << i;
  }
  // Frees from other threads still find the owner.
  std::thread freeing([&] {
    for (int i = 0; i < rounds; ++i) {
      router.free(inside[i]);
      router.free(outside[i]);
    }
  });
  freeing.join();
  EXPECT_EQ(FakePool::frees, rounds);
  EXPECT_EQ(system_counts.free, rounds);
  EXPECT_TRUE(FakePool::tlsf->check());
}

TEST_F(HeapRouterTest, AnotherThreadCanEndAScopeThroughItsToken) {
  void* token = HeapRouter::enter_scope();
  std::thread publisher([&] { HeapRouter::leave_scope(token); });
  publisher.join();
  EXPECT_FALSE(HeapRouter::in_scope());
}

}  // namespace
}  // namespace agnocast::heaphook
