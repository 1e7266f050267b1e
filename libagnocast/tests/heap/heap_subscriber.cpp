// Receives seed::Msg from heap_publisher without the allocation hook (it only
// reads), checks every message, then searches the publisher's whole pool, as
// this process sees it, for the secret the publisher kept private.
// usage: heap_subscriber TOPIC TOTAL SECRET
#include <agnocast/agnocast.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pool_mapping.hpp"
#include "seed_message_agnocast.hpp"

namespace {

// Why message msg is not what the publisher wrote, or empty.
std::string check(const seed::Msg& msg) {
  const std::uint64_t seq = msg.seq;
  const seed::Mapping pool = seed::mapping_of(&msg);
  for (const void* member :
       {static_cast<const void*>(msg.payload.data()), static_cast<const void*>(msg.frame_id.data()),
        static_cast<const void*>(msg.points.data()), static_cast<const void*>(msg.tags.data())}) {
    if (!pool.contains(member)) return "a member lies outside the publisher's pool";
  }
  if (msg.payload.size() != seed::payload_size(seq)) return "payload size";
  for (std::size_t i = 0; i < msg.payload.size(); ++i) {
    if (msg.payload[i] != seed::payload_byte(seq, i)) return "payload byte " + std::to_string(i);
  }
  if (msg.frame_id != seed::frame_id(seq)) return "frame_id '" + msg.frame_id + "'";
  if (msg.points.size() != seed::point_count(seq)) return "point count";
  for (std::size_t i = 0; i < msg.points.size(); ++i) {
    const seed::Point& point = msg.points[i];
    if (point.x != static_cast<double>(seq) || point.y != static_cast<double>(i) ||
        point.z != 0.5) {
      return "point " + std::to_string(i);
    }
  }
  if (msg.tags.size() != seed::tag_count(seq)) return "tag count";
  for (std::size_t t = 0; t < msg.tags.size(); ++t) {
    const seed::Tag& tag = msg.tags[t];
    if (!pool.contains(tag.key.data()) || !pool.contains(tag.values.data())) {
      return "a nested member lies outside the publisher's pool";
    }
    if (tag.key != "key " + std::to_string(t) + " of message " + std::to_string(seq)) {
      return "tag key '" + tag.key + "'";
    }
    if (tag.values != std::vector<std::int32_t>(t + 3, static_cast<std::int32_t>(seq))) {
      return "tag values";
    }
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: heap_subscriber TOPIC TOTAL SECRET\n");
    return 2;
  }
  const std::string topic = argv[1];
  const std::size_t total = std::strtoull(argv[2], nullptr, 10);
  std::string secret;
  for (int i = 0; i < 64; ++i) secret += argv[3];
  if (agnocast::heap_scope::hook_active()) {
    std::fprintf(stderr, "heap_subscriber: runs with the hook, but must not\n");
    return 1;
  }
  std::vector<bool> seen(total, false);
  std::size_t received = 0;
  std::string failure;
  agnocast::ipc_shared_ptr<const seed::Msg> last;
  // The pool is as large as the module's pool_size: search the part the
  // messages used and well beyond it, where the allocator would have put
  // anything else allocated in the scope.
  std::uintptr_t used_end = 0;
  try {
    agnocast::Node node{"heap_subscriber"};
    auto subscription = node.create_subscription<seed::Msg>(
        topic, agnocast::QoS{1000}, [&](const agnocast::ipc_shared_ptr<const seed::Msg>& msg) {
          const std::string why = check(*msg);
          if (!why.empty() && failure.empty()) {
            failure = "message " + std::to_string(msg->seq) + ": " + why;
          }
          if (msg->seq < total && !seen[msg->seq]) {
            seen[msg->seq] = true;
            ++received;
          }
          last = msg;
          used_end = std::max(used_end, reinterpret_cast<std::uintptr_t>(msg.get() + 1));
          for (const void* member : {static_cast<const void*>(msg->payload.data()),
                                     static_cast<const void*>(msg->points.data())}) {
            used_end = std::max(used_end, reinterpret_cast<std::uintptr_t>(member));
          }
        });
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(90);
    while (received < total && failure.empty() && std::chrono::steady_clock::now() < deadline) {
      executor.spin_once(std::chrono::milliseconds(100));
    }
    if (failure.empty() && received < total) {
      failure = "received " + std::to_string(received) + " of " + std::to_string(total);
    }
    if (failure.empty()) {
      const seed::Mapping pool = seed::mapping_of(last.get());
      const std::uintptr_t margin = 16 << 20;
      const char* begin = reinterpret_cast<const char*>(pool.begin);
      const char* end = reinterpret_cast<const char*>(std::min(pool.end, used_end + margin));
      if (std::search(begin, end, secret.begin(), secret.end()) != end) {
        failure = "the publisher's secret is readable in its pool";
      }
    }
    last.reset();
  } catch (const std::exception& error) {
    failure = error.what();
  }
  if (!failure.empty()) {
    std::fprintf(stderr, "heap_subscriber: %s\n", failure.c_str());
    return 1;
  }
  std::printf("received %zu intact, secret not in the pool\n", received);
  return 0;
}
