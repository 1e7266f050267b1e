#include "agnocast/ipc_shared_ptr.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <type_traits>
#include <vector>

#include "agnocast/allocator.hpp"
#include "kernel/fake_kernel.hpp"
#include "kernel/runtime.hpp"

namespace agnocast::detail {
namespace {

// Stands in for the kernel subscriber: counts RELEASE calls and frees each
// reference handed back.
class FakeSubscriber : public EntryOwner {
 public:
  void release_entry(std::uint64_t entry_id) noexcept override {
    released.fetch_add(1);
    last_released.store(entry_id);
  }
  void recycle(EntryReference* reference) noexcept override {
    recycled.fetch_add(1);
    delete reference;
  }
  std::atomic<int> released{0};
  std::atomic<int> recycled{0};
  std::atomic<std::uint64_t> last_released{0};
};

struct Message {
  int value = 7;
  agnocast::vector<int> numbers;
};

ipc_shared_ptr<const int> received(const int* message, std::shared_ptr<FakeSubscriber> owner,
                                   std::uint64_t entry_id) {
  auto* reference = new EntryReference;
  reference->owner = std::move(owner);
  reference->entry_id = entry_id;
  return MessageAccess::received(message, reference);
}

static_assert(std::is_copy_constructible_v<ipc_shared_ptr<const Message>>);
static_assert(std::is_copy_assignable_v<ipc_shared_ptr<const Message>>);
static_assert(!std::is_copy_constructible_v<ipc_shared_ptr<Message>>,
              "a loan is move-only until it is published");
static_assert(!std::is_copy_assignable_v<ipc_shared_ptr<Message>>);
static_assert(std::is_nothrow_move_constructible_v<ipc_shared_ptr<Message>>);

TEST(IpcSharedPtr, LastCopyReleasesOnce) {
  auto owner = std::make_shared<FakeSubscriber>();
  const int value = 42;
  {
    auto first = received(&value, owner, 9);
    EXPECT_EQ(first.use_count(), 1U);
    EXPECT_EQ(first.entry_id(), 9U);
    auto second = first;
    ipc_shared_ptr<const int> third;
    third = second;
    EXPECT_EQ(first.use_count(), 3U);
    EXPECT_EQ(*third, 42);
    first.reset();
    second.reset();
    EXPECT_EQ(owner->released.load(), 0);
  }
  EXPECT_EQ(owner->released.load(), 1);
  EXPECT_EQ(owner->last_released.load(), 9U);
  EXPECT_EQ(owner->recycled.load(), 1);
}

TEST(IpcSharedPtr, MoveLeavesTheSourceEmpty) {
  auto owner = std::make_shared<FakeSubscriber>();
  const int value = 1;
  auto first = received(&value, owner, 1);
  auto second = std::move(first);
  EXPECT_FALSE(first);
  EXPECT_TRUE(second);
  EXPECT_EQ(second.use_count(), 1U);
  second = ipc_shared_ptr<const int>();
  EXPECT_EQ(owner->released.load(), 1);
}

TEST(IpcSharedPtr, SelfAssignmentKeepsTheReference) {
  auto owner = std::make_shared<FakeSubscriber>();
  const int value = 1;
  auto pointer = received(&value, owner, 1);
  auto& alias = pointer;
  pointer = alias;
  pointer = std::move(alias);
  EXPECT_TRUE(pointer);
  EXPECT_EQ(owner->released.load(), 0);
}

TEST(IpcSharedPtr, ConcurrentCopiesReleaseExactlyOnce) {
  auto owner = std::make_shared<FakeSubscriber>();
  const int value = 1;
  for (int round = 0; round < 50; ++round) {
    auto shared = received(&value, owner, round);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
      threads.emplace_back([copy = shared] {
        for (int i = 0; i < 1000; ++i) {
          auto again = copy;
          again.reset();
        }
      });
    }
    shared.reset();
    for (auto& thread : threads) thread.join();
  }
  EXPECT_EQ(owner->released.load(), 50);
}

class PoolTest : public ::testing::Test {
 protected:
  static constexpr std::size_t pool_size = 16 << 20;
  void SetUp() override {
    region_ = new (std::align_val_t{4096}) std::byte[pool_size];
    runtime_ = &Runtime::install_for_testing(region_, pool_size, std::make_unique<FakeKernel>());
    baseline_ = runtime_->pool_stats();
  }
  // The region is left to the leaked runtime: pointers into it may survive a test.
  void ExpectPoolBackToBaseline() {
    const Tlsf::Stats now = runtime_->pool_stats();
    EXPECT_EQ(now.used_blocks, baseline_.used_blocks);
    EXPECT_EQ(now.free_bytes, baseline_.free_bytes);
  }
  std::byte* region_ = nullptr;
  Runtime* runtime_ = nullptr;
  Tlsf::Stats baseline_;
};

TEST_F(PoolTest, UnpublishedLoanIsDestroyedAndFreedWithNestedContainers) {
  {
    void* memory =
        allocate_message(sizeof(Message), alignof(Message), &destroy_message_object<Message>);
    auto loan = MessageAccess::loan(new (memory) Message());
    EXPECT_TRUE(runtime_->owns(loan.get()));
    loan->numbers.assign(100000, 3);
    EXPECT_TRUE(runtime_->owns(loan->numbers.data()));
    EXPECT_EQ(loan.use_count(), 0U);
  }
  ExpectPoolBackToBaseline();
}

TEST_F(PoolTest, ReleaseLoanHandsOverOwnership) {
  void* memory =
      allocate_message(sizeof(Message), alignof(Message), &destroy_message_object<Message>);
  auto loan = MessageAccess::loan(new (memory) Message());
  Message* message = MessageAccess::release_loan(loan);
  EXPECT_FALSE(loan);
  EXPECT_EQ(MessageAccess::release_loan(loan), nullptr);
  // What the runtime does when the kernel reports the message reclaimable:
  const std::uint64_t address = reinterpret_cast<std::uintptr_t>(message);
  runtime_->free_reclaimed(std::span(&address, 1));
  ExpectPoolBackToBaseline();
}

TEST_F(PoolTest, OverAlignedMessagesStayAligned) {
  struct alignas(256) Wide {
    char bytes[300];
  };
  void* memory = allocate_message(sizeof(Wide), alignof(Wide), &destroy_message_object<Wide>);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(memory) % 256, 0U);
  discard_message(new (memory) Wide());
  ExpectPoolBackToBaseline();
}

TEST_F(PoolTest, ContainersNestAtAnyDepth) {
  {
    using Inner = agnocast::vector<agnocast::string>;
    agnocast::vector<Inner> nested(3);
    for (auto& inner : nested) {
      inner.emplace_back("a string long enough to leave the small-string buffer behind");
      inner.emplace_back("short");
    }
    nested.emplace_back(nested.front());
    EXPECT_TRUE(runtime_->owns(nested.data()));
    EXPECT_TRUE(runtime_->owns(nested[3].data()));
    EXPECT_TRUE(runtime_->owns(nested[3][0].data()));
    EXPECT_EQ(nested[3][0], nested[0][0]);
  }
  ExpectPoolBackToBaseline();
}

TEST_F(PoolTest, ExhaustionThrowsBadAllocNamingTheSetting) {
  try {
    agnocast::vector<char> huge(pool_size * 2);
    ADD_FAILURE() << "allocated more than the pool";
  } catch (const std::bad_alloc& error) {
    EXPECT_NE(std::string(error.what()).find("pool_size"), std::string::npos) << error.what();
  }
  std::vector<agnocast::vector<char>> held;
  EXPECT_THROW(for (;;) held.emplace_back(1 << 20, 'x'), std::bad_alloc);
  held.clear();
  ExpectPoolBackToBaseline();
}

TEST_F(PoolTest, ForeignPointersAreNeverFreedIntoThePool) {
  int outside = 0;
  pool_deallocate(&outside);
  ExpectPoolBackToBaseline();
}

}  // namespace
}  // namespace agnocast::detail
