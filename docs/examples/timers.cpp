// A periodic node: publishes at 20 Hz once someone listens, and stops after
// 100 messages by cancelling its timer.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>

#include "robot_messages.hpp"

int main() {
  using namespace std::chrono_literals;
  agnocast::Node node{"odometry"};
  auto publisher = node.create_publisher<robot::Pose>("/pose", agnocast::QoS{10});
  if (!publisher->wait_for_subscribers(1, 10s)) {
    std::printf("nobody subscribed to /pose within 10 s\n");
    return 1;
  }
  agnocast::SingleThreadedExecutor executor;
  int sent = 0;
  std::shared_ptr<agnocast::Timer> timer;
  timer = node.create_wall_timer(50ms, [&] {
    auto pose = publisher->borrow_loaned_message();
    pose->x = 0.01 * sent;
    publisher->publish(std::move(pose));
    if (++sent == 100) {
      timer->cancel();
      executor.cancel();  // spin() returns
    }
  });
  executor.add_node(node);
  executor.spin();
  std::printf("sent %d poses to %zu subscribers\n", sent, publisher->get_subscription_count());
}
