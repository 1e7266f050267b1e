// A test runtime over a heap region with a FakeKernel, for native tests of
// publishers, subscriptions and executors.
#pragma once

#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <utility>

#include "agnocast/publisher.hpp"
#include "kernel/fake_kernel.hpp"
#include "kernel/runtime.hpp"

namespace agnocast::detail {

// A message that records nothing but its sequence number.
struct Counted {
  std::uint64_t seq = 0;
};

class FakeRuntimeTest : public ::testing::Test {
 protected:
  static constexpr std::size_t pool_size = 4 << 20;

  void SetUp() override {
    auto kernel = std::make_unique<FakeKernel>();
    kernel_ = kernel.get();
    // Leaked with the runtime on purpose: pointers into it may survive a test.
    region_ = new (std::align_val_t{4096}) std::byte[pool_size];
    runtime_ = &Runtime::install_for_testing(region_, pool_size, std::move(kernel));
  }

  // Unique among concurrently running test binaries: queues are system-wide.
  std::string topic(const std::string& name) const {
    return "/native_" + std::to_string(::getpid()) + "_" + name;
  }

  FakeKernel& kernel() { return *kernel_; }
  Runtime& runtime() { return *runtime_; }
  const void* runtime_region() const { return region_; }

 private:
  FakeKernel* kernel_ = nullptr;
  Runtime* runtime_ = nullptr;
  std::byte* region_ = nullptr;
};

// Publishes one Counted message numbered `seq`.
inline void publish(Publisher<Counted>& publisher, std::uint64_t seq) {
  auto message = publisher.borrow_loaned_message();
  message->seq = seq;
  publisher.publish(std::move(message));
}

// Whether `fd` is readable now, without waiting.
inline bool readable(int fd) {
  pollfd entry{fd, POLLIN, 0};
  return ::poll(&entry, 1, 0) == 1;
}

}  // namespace agnocast::detail
