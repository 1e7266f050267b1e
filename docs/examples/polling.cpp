// A consumer that wants the newest pose at its own rate, next to a callback
// subscription, without checking deadlines by hand: a polling subscriber read
// from a timer.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>

#include "robot_messages.hpp"

int main() {
  using namespace std::chrono_literals;
  agnocast::Node node{"planner"};
  auto poses = node.create_polling_subscriber<robot::Pose>("/pose", agnocast::QoS{1});
  auto scans = node.create_subscription<robot::Scan>(
      "/scan", agnocast::QoS{10}, [](const robot::Scan& scan) { (void)scan.ranges.size(); });

  auto plan = node.create_wall_timer(100ms, [&] {
    // The newest pose within depth; the same one again if none came since.
    const agnocast::ipc_shared_ptr<const robot::Pose> pose = poses->take_data();
    if (!pose) return;  // nothing published yet
    std::printf("planning from x=%.2f\n", pose->x);
  });
  auto watchdog = node.create_wall_timer(500ms, [&] {
    // Only a pose not taken before: empty tells that none arrived.
    if (!poses->take_new_data()) std::printf("no new pose for a while\n");
  });

  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
}
