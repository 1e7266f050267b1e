#include "kernel/runtime.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <memory>
#include <new>
#include <string>

#include "agnocast/errors.hpp"
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

// A pool granted where this process already has a mapping is refused, named,
// and under AddressSanitizer (whose shadow a module's pool_base may lie in)
// with the parameter that moves the pools out of it.
TEST(PoolMapping, AnOccupiedRangeIsRefusedWithTheWayOut) {
  auto* own = new (std::align_val_t{4096}) std::byte[pool_size];
  Runtime& runtime = Runtime::install_for_testing(own, pool_size, std::make_unique<FakeKernel>());
  void* taken = ::mmap(nullptr, pool_size, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(taken, MAP_FAILED);
  PoolGrant grant = publisher_pool();
  grant.addr = reinterpret_cast<std::uint64_t>(taken);
  std::string message;
  try {
    runtime.map_pool(grant);
  } catch (const Error& error) {
    message = error.what();
  }
  ::munmap(taken, pool_size);
  EXPECT_NE(message.find("cannot map the pool of publisher pid 4242"), std::string::npos)
      << message;
  EXPECT_NE(message.find("something else occupies that address range"), std::string::npos)
      << message;
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_NE(message.find("a pool_base above 0x10007fff8000"), std::string::npos) << message;
#else
  EXPECT_EQ(message.find("AddressSanitizer"), std::string::npos) << message;
#endif
  EXPECT_TRUE(runtime.pool_holding(taken).empty());
}

}  // namespace
}  // namespace agnocast::detail
