#include "kernel/runtime.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <memory>
#include <new>

#include "kernel/fake_kernel.hpp"

namespace agnocast::detail {
namespace {

constexpr std::size_t pool_size = 1 << 16;

// A publisher's pool as a memfd granted at an address free in this process.
PoolGrant publisher_pool() {
  void* probe = ::mmap(nullptr, pool_size, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  EXPECT_NE(probe, MAP_FAILED);
  ::munmap(probe, pool_size);
  const int fd = ::memfd_create("runtime_test_pool", MFD_CLOEXEC);
  EXPECT_EQ(::ftruncate(fd, pool_size), 0);
  return {reinterpret_cast<std::uint64_t>(probe), pool_size, fd, 4242};
}

TEST(PoolHolding, FindsTheOwnOrMappedPoolThatHoldsAnAddress) {
  auto* own = new (std::align_val_t{4096}) std::byte[pool_size];
  Runtime& runtime = Runtime::install_for_testing(own, pool_size, std::make_unique<FakeKernel>());
  const PoolGrant grant = publisher_pool();
  runtime.map_pool(grant);
  const auto* mapped = reinterpret_cast<const std::byte*>(grant.addr);

  EXPECT_EQ(runtime.pool_holding(own + 100).data(), own);
  EXPECT_EQ(runtime.pool_holding(own + 100).size(), pool_size);
  EXPECT_EQ(runtime.pool_holding(mapped).data(), mapped);
  EXPECT_EQ(runtime.pool_holding(mapped + pool_size - 1).size(), pool_size);
  EXPECT_TRUE(runtime.pool_holding(mapped + pool_size).empty());
  EXPECT_TRUE(runtime.pool_holding(own + pool_size).empty());
  const int on_the_stack = 0;
  EXPECT_TRUE(runtime.pool_holding(&on_the_stack).empty());
}

}  // namespace
}  // namespace agnocast::detail
