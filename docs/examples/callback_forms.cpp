// The four callback forms a subscription accepts, and what MessageInfo tells.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>
#include <vector>

#include "robot_messages.hpp"

int main() {
  agnocast::Node node{"callback_forms"};
  const agnocast::QoS qos{10};

  // 1. A reference: read the message in place, for the callback's duration.
  auto by_reference = node.create_subscription<robot::Pose>(
      "/pose", qos,
      [](const robot::Pose& pose) { std::printf("x=%.2f y=%.2f\n", pose.x, pose.y); });

  // 2. A shared pointer: keep the message beyond the callback (no copy);
  //    the publisher reuses its memory only after the last pointer goes.
  std::vector<agnocast::ipc_shared_ptr<const robot::Pose>> history;
  auto by_pointer = node.create_subscription<robot::Pose>(
      "/pose", qos,
      [&](const agnocast::ipc_shared_ptr<const robot::Pose>& pose) { history.push_back(pose); });

  // 3. and 4. Either form plus MessageInfo: who published, when, how large.
  auto with_info = node.create_subscription<robot::Pose>(
      "/pose", qos, [](const robot::Pose&, const agnocast::MessageInfo& info) {
        const auto now = std::chrono::steady_clock::now().time_since_epoch();
        const auto latency = std::chrono::nanoseconds(now).count() - info.publish_time;
        std::printf("entry %llu from publisher %u: %llu bytes, %lld ns after publish\n",
                    static_cast<unsigned long long>(info.entry_id), info.publisher_id,
                    static_cast<unsigned long long>(info.bytes), static_cast<long long>(latency));
      });
  auto pointer_with_info = node.create_subscription<robot::Pose>(
      "/pose", qos,
      [](const agnocast::ipc_shared_ptr<const robot::Pose>&, const agnocast::MessageInfo&) {});

  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
}
