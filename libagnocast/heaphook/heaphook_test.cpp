// The hook in a real process: this test binary is linked with
// libagnocast_heaphook.so, so its malloc is the hook's, and its pool is a
// test runtime's region (a FakeKernel carries messages within the process).
#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/heap_scope.hpp"
#include "agnocast/node.hpp"
#include "kernel/fake_runtime.hpp"
#include "seed_message_agnocast.hpp"

namespace agnocast::detail {
namespace {

class HeapHookTest : public FakeRuntimeTest {
 protected:
  bool in_pool(const void* ptr) { return runtime().owns(ptr); }

  // Every heap block the message points to is in the pool.
  void expect_in_pool(const seed::Msg& msg) {
    EXPECT_TRUE(in_pool(msg.payload.data()));
    EXPECT_TRUE(in_pool(msg.frame_id.data()));
    EXPECT_TRUE(in_pool(msg.points.data()));
    EXPECT_TRUE(in_pool(msg.tags.data()));
    for (const seed::Tag& tag : msg.tags) {
      EXPECT_TRUE(in_pool(tag.key.data()));
      EXPECT_TRUE(in_pool(tag.values.data()));
    }
  }

  static void fill(seed::Msg& msg, std::uint64_t seq) {
    msg.seq = seq;
    msg.payload.resize(1000, 7);
    msg.payload.resize(50000, 9);  // grows during the scope
    msg.frame_id = "a frame id longer than any short-string buffer #" + std::to_string(seq);
    for (int i = 0; i < 300; ++i) msg.points.push_back({1.0 * i, 2.0 * i, 3.0 * i});
    for (int i = 0; i < 5; ++i) {
      msg.tags.push_back({"tag number " + std::to_string(i) + " with a long enough key",
                          std::vector<std::int32_t>(100 + i, i)});
    }
  }

  static void check(const seed::Msg& msg, std::uint64_t seq) {
    EXPECT_EQ(msg.seq, seq);
    ASSERT_EQ(msg.payload.size(), 50000U);
    EXPECT_EQ(msg.payload[999], 7);
    EXPECT_EQ(msg.payload[49999], 9);
    EXPECT_EQ(msg.frame_id,
              "a frame id longer than any short-string buffer #" + std::to_string(seq));
    ASSERT_EQ(msg.points.size(), 300U);
    EXPECT_EQ(msg.points[299].z, 897.0);
    ASSERT_EQ(msg.tags.size(), 5U);
    EXPECT_EQ(msg.tags[4].key, "tag number 4 with a long enough key");
    EXPECT_EQ(msg.tags[4].values, std::vector<std::int32_t>(104, 4));
  }
};

TEST_F(HeapHookTest, IsActiveWhenLinked) { EXPECT_TRUE(heap_scope::hook_active()); }

TEST_F(HeapHookTest, AFilledLoanLivesInThePoolAndArrivesIntact) {
  Node node{"heap"};
  auto subscriber = node.create_polling_subscriber<seed::Msg>(topic("seed"), QoS{1});
  auto publisher = node.create_publisher<seed::Msg>(topic("seed"), QoS{1});
  auto msg = publisher->borrow_loaned_message();
  fill(*msg, 42);
  expect_in_pool(*msg);
  publisher->publish(std::move(msg));
  const auto received = subscriber->take_data();
  ASSERT_TRUE(received);
  check(*received, 42);
}

TEST_F(HeapHookTest, TheScopeEndsAtPublishAndWhenALoanIsDropped) {
  Node node{"heap"};
  auto publisher = node.create_publisher<seed::Msg>(topic("ends"), QoS{1});
  {
    auto msg = publisher->borrow_loaned_message();
    auto inside = std::make_unique<int>(1);
    EXPECT_TRUE(in_pool(inside.get()));
    publisher->publish(std::move(msg));
  }
  auto after_publish = std::make_unique<int>(2);
  EXPECT_FALSE(in_pool(after_publish.get()));
  {
    auto dropped = publisher->borrow_loaned_message();
    dropped->payload.resize(100);
  }
  auto after_drop = std::make_unique<int>(3);
  EXPECT_FALSE(in_pool(after_drop.get()));
}

TEST_F(HeapHookTest, ASecretAllocatedOutsideTheScopeNeverReachesThePool) {
  Node node{"heap"};
  auto publisher = node.create_publisher<seed::Msg>(topic("secret"), QoS{1});
  // Built at run time, so that its bytes exist only where it is allocated.
  std::string marker(4096, '\0');
  for (std::size_t i = 0; i < marker.size(); ++i) marker[i] = static_cast<char>('A' + i * 7 % 26);
  std::string before = marker;
  auto msg = publisher->borrow_loaned_message();
  fill(*msg, 1);
  std::string on_another_thread;
  std::thread([&] { on_another_thread = marker; }).join();  // not the borrowing thread
  publisher->publish(std::move(msg));
  std::string after = marker;
  for (const std::string* secret : {&marker, &before, &on_another_thread, &after}) {
    EXPECT_FALSE(in_pool(secret->data()));
  }
  const auto* pool = static_cast<const char*>(runtime_region());
  EXPECT_EQ(std::search(pool, pool + pool_size, marker.begin(), marker.end()), pool + pool_size)
      << "the secret's bytes are in the pool";
}

TEST_F(HeapHookTest, AnExplicitScopeLetsAnotherThreadFillTheLoan) {
  Node node{"heap"};
  auto subscriber = node.create_polling_subscriber<seed::Msg>(topic("filler"), QoS{1});
  auto publisher = node.create_publisher<seed::Msg>(topic("filler"), QoS{1});
  auto msg = publisher->borrow_loaned_message();
  std::thread([&] {
    heap_scope scope;
    fill(*msg, 5);
  }).join();
  expect_in_pool(*msg);
  publisher->publish(std::move(msg));
  check(*subscriber->take_data(), 5);
}

TEST_F(HeapHookTest, PublishersOnManyThreadsKeepTheirScopesApart) {
  Node node{"heap"};
  constexpr int threads = 4, rounds = 50;
  std::atomic<int> private_in_pool{0};
  std::vector<std::shared_ptr<Publisher<seed::Msg>>> publishers;
  for (int t = 0; t < threads; ++t) {
    publishers.push_back(node.create_publisher<seed::Msg>(topic("threads"), QoS{2}));
  }
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t) {
    workers.emplace_back([&, t] {
      Publisher<seed::Msg>& publisher = *publishers[t];
      for (int i = 0; i < rounds; ++i) {
        auto msg = publisher.borrow_loaned_message();
        fill(*msg, static_cast<std::uint64_t>(t * rounds + i));
        expect_in_pool(*msg);
        publisher.publish(std::move(msg));
        auto scratch = std::make_unique<std::vector<int>>(64);
        if (in_pool(scratch.get()) || in_pool(scratch->data())) ++private_in_pool;
      }
    });
  }
  for (std::thread& worker : workers) worker.join();
  EXPECT_EQ(private_in_pool, 0);
  runtime().reclaim_all();
}

TEST_F(HeapHookTest, AFullPoolIsBadAllocAndEnomem) {
  heap_scope scope;
  EXPECT_THROW(std::vector<char>(2 * pool_size), std::bad_alloc);
  errno = 0;
  EXPECT_EQ(std::malloc(2 * pool_size), nullptr);
  EXPECT_EQ(errno, ENOMEM);
  void* small = std::malloc(100);
  EXPECT_TRUE(in_pool(small));
  EXPECT_GE(malloc_usable_size(small), 100U);
  std::free(small);
}

TEST_F(HeapHookTest, AForkChildAllocatesPrivately) {
  heap_scope scope;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    void* ptr = std::malloc(100);
    ::_exit(runtime().owns(ptr) ? 1 : 0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
}

}  // namespace
}  // namespace agnocast::detail
