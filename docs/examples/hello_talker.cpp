// Publishes a scan ten times a second until Ctrl-C.
#include <agnocast/agnocast.hpp>
#include <chrono>

#include "robot_messages.hpp"

int main() {
  agnocast::Node node{"hello_talker"};
  auto publisher = node.create_publisher<robot::Scan>("/scan", agnocast::QoS{10});
  std::uint64_t seq = 0;
  auto timer = node.create_wall_timer(std::chrono::milliseconds{100}, [&] {
    agnocast::ipc_shared_ptr<robot::Scan> scan = publisher->borrow_loaned_message();
    scan->seq = seq++;
    scan->frame_id = "laser";
    scan->ranges.assign(360, 1.5F);       // allocated in shared memory
    publisher->publish(std::move(scan));  // zero copies
  });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();  // returns on Ctrl-C (SIGINT) or SIGTERM
}
