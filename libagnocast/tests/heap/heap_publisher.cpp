// Publishes seed::Msg, a type with std::vector/std::string members, with the
// allocation hook (LD_PRELOAD, or linked: the same source builds both).
// usage: heap_publisher TOPIC COUNT THREADS MODE SECRET
//   MODE threads: one std::thread per publisher; executor: one timer per
//   publisher on a MultiThreadedExecutor. SECRET is allocated outside any
//   loan scope, before, during and after the loans; it must not reach the pool.
// Exit 0 when every message was published with all its members in the pool.
#include <agnocast/agnocast.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pool_mapping.hpp"
#include "seed_message_agnocast.hpp"

namespace {

std::atomic<int> failures{0};

void fail(const std::string& what) {
  std::fprintf(stderr, "heap_publisher: %s\n", what.c_str());
  ++failures;
}

// Copies of the secret the subscriber looks for: held privately the whole time.
std::mutex secrets_mutex;
std::vector<std::string> secrets;

void keep_secret(const std::string& secret) {
  std::lock_guard lock(secrets_mutex);
  secrets.push_back(secret);
}

// Fills the loan the way ordinary code does: resizes, grows one element at a
// time, nests vectors and strings in a vector.
void fill(seed::Msg& msg, std::uint64_t seq, const std::string& secret) {
  msg.seq = seq;
  msg.payload.resize(10);
  for (std::size_t i = 0; i < msg.payload.size(); ++i) msg.payload[i] = seed::payload_byte(seq, i);
  for (std::size_t i = 10; i < seed::payload_size(seq); ++i) {
    msg.payload.push_back(seed::payload_byte(seq, i));  // reallocates as it grows
  }
  msg.frame_id = seed::frame_id(seq);
  msg.points.resize(seed::point_count(seq));
  for (std::size_t i = 0; i < msg.points.size(); ++i) {
    msg.points[i] = {static_cast<double>(seq), static_cast<double>(i), 0.5};
  }
  for (std::size_t t = 0; t < seed::tag_count(seq); ++t) {
    seed::Tag tag;
    tag.key = "key " + std::to_string(t) + " of message " + std::to_string(seq);
    tag.values.assign(t + 3, static_cast<std::int32_t>(seq));
    msg.tags.push_back(std::move(tag));
  }
  // A C buffer grown with realloc inside the scope moves into the pool.
  char* grown = static_cast<char*>(std::malloc(8));
  std::strcpy(grown, "grow");
  grown = static_cast<char*>(std::realloc(grown, 100000));
  const seed::Mapping pool = seed::mapping_of(&msg);
  if (!pool.contains(grown) || std::strcmp(grown, "grow") != 0) fail("realloc left the pool");
  std::free(grown);
  // A private copy made on another thread during the loan stays private.
  std::thread([&] { keep_secret(secret); }).join();
  for (const void* member :
       {static_cast<const void*>(msg.payload.data()), static_cast<const void*>(msg.frame_id.data()),
        static_cast<const void*>(msg.points.data()), static_cast<const void*>(msg.tags.data())}) {
    if (!pool.contains(member)) fail("a member of message " + std::to_string(seq) + " is private");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: heap_publisher TOPIC COUNT THREADS threads|executor SECRET\n");
    return 2;
  }
  const std::string topic = argv[1];
  const int count = std::atoi(argv[2]);
  const int threads = std::atoi(argv[3]);
  const bool on_executor = std::strcmp(argv[4], "executor") == 0;
  // Built at run time from the argument: its bytes exist only where allocated.
  std::string secret;
  for (int i = 0; i < 64; ++i) secret += argv[5];
  keep_secret(secret);
  try {
    agnocast::Node node{"heap_publisher"};
    std::vector<std::shared_ptr<agnocast::Publisher<seed::Msg>>> publishers;
    for (int t = 0; t < threads; ++t) {
      publishers.push_back(node.create_publisher<seed::Msg>(topic, agnocast::QoS{100}));
    }
    if (!publishers[0]->wait_for_subscribers(1, std::chrono::seconds(30))) {
      fail("no subscriber");
      return 1;
    }
    auto publish = [&](int t, int i) {
      const auto seq = static_cast<std::uint64_t>(t * count + i);
      auto msg = publishers[t]->borrow_loaned_message();
      fill(*msg, seq, secret);
      publishers[t]->publish(std::move(msg));
    };
    if (on_executor) {
      agnocast::MultiThreadedExecutor executor(static_cast<std::size_t>(threads));
      std::vector<std::shared_ptr<agnocast::Timer>> timers;
      std::vector<int> sent(threads, 0);
      std::atomic<int> done{0};
      for (int t = 0; t < threads; ++t) {
        auto group = node.create_callback_group(agnocast::CallbackGroupType::MutuallyExclusive);
        timers.push_back(node.create_wall_timer(
            std::chrono::milliseconds(5),
            [&, t] {
              if (sent[t] == count) return;
              publish(t, sent[t]++);
              if (sent[t] == count && ++done == threads) executor.cancel();
            },
            group));
      }
      executor.add_node(node);
      executor.spin();
    } else {
      std::vector<std::thread> workers;
      for (int t = 0; t < threads; ++t) {
        workers.emplace_back([&, t] {
          for (int i = 0; i < count; ++i) publish(t, i);
        });
      }
      for (std::thread& worker : workers) worker.join();
    }
    keep_secret(secret);  // and once more after the last publish
    // The pool stays until the subscriber has read it all.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (publishers[0]->get_subscription_count() > 0 &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  } catch (const std::exception& error) {
    fail(error.what());
    return 3;
  }
  if (failures > 0) return 1;
  std::printf("published %d\n", count * threads);
  return 0;
}
