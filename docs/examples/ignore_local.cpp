// Two planners share a /obstacles topic: each publishes what it sees and
// subscribes to what the others see, but not to its own messages. The kernel
// filters them, so they never take the subscription's depth.
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>

#include "robot_messages.hpp"

int main() {
  using namespace std::chrono_literals;
  agnocast::Node node{"planner_" + std::to_string(::getpid())};
  auto publisher = node.create_publisher<robot::Pose>("/obstacles", agnocast::QoS{10});
  agnocast::SubscriptionOptions options;
  options.ignore_local_publications = true;
  auto subscription = node.create_subscription<robot::Pose>(
      "/obstacles", agnocast::QoS{10},
      [](const robot::Pose&, const agnocast::MessageInfo& info) {
        std::printf("obstacle from publisher %u\n", info.publisher_id);
      },
      options);
  auto report = node.create_wall_timer(
      200ms, [&] { publisher->publish(publisher->borrow_loaned_message()); });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
}
