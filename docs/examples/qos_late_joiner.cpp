// A map server publishes once; a subscriber started later still gets the map,
// because both sides are transient-local.
#include <agnocast/agnocast.hpp>
#include <cstdio>
#include <string_view>

#include "robot_messages.hpp"

int main(int argc, char** argv) {
  const bool server = argc > 1 && std::string_view(argv[1]) == "server";
  agnocast::Node node{server ? "map_server" : "map_user"};
  const auto qos = agnocast::QoS{1}.transient_local();
  if (server) {
    auto publisher = node.create_publisher<robot::Scan>("/map", qos);
    auto map = publisher->borrow_loaned_message();
    map->frame_id = "map";
    map->ranges.assign(1 << 20, 0.0F);
    publisher->publish(std::move(map));
    // The kernel keeps the newest `depth` messages only while the publisher
    // exists: stay alive to serve late joiners.
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    executor.spin();
    return 0;
  }
  auto subscription = node.create_subscription<robot::Scan>("/map", qos, [](const robot::Scan& m) {
    std::printf("got the map: %zu cells\n", m.ranges.size());
  });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
}
