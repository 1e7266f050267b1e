// A MultiThreadedExecutor runs callbacks in parallel as their groups allow:
// the control loop and the pose subscription share state, so they share a
// MutuallyExclusive group; the two slow diagnostics may run at the same time
// as anything, so they sit in a Reentrant group.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <thread>

#include "robot_messages.hpp"

int main() {
  using namespace std::chrono_literals;
  agnocast::Node node{"controller"};
  auto control = node.create_callback_group(agnocast::CallbackGroupType::MutuallyExclusive);
  auto diagnostics = node.create_callback_group(agnocast::CallbackGroupType::Reentrant);

  robot::Pose latest;   // touched only by callbacks of `control`: never concurrently
  double steering = 0;  // likewise
  agnocast::SubscriptionOptions options;
  options.callback_group = control;
  auto poses = node.create_subscription<robot::Pose>(
      "/pose", agnocast::QoS{10}, [&](const robot::Pose& pose) { latest = pose; }, options);
  auto loop = node.create_wall_timer(
      10ms, [&] { steering = -0.5 * latest.yaw; }, control);

  auto slow_check = [] { std::this_thread::sleep_for(50ms); };
  auto battery = node.create_wall_timer(100ms, slow_check, diagnostics);
  auto motors = node.create_wall_timer(100ms, slow_check, diagnostics);

  agnocast::MultiThreadedExecutor executor(4);  // 4 threads; 0: one per CPU
  executor.add_node(node);
  executor.spin();
}
