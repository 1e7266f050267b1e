// Prints every scan it receives until Ctrl-C.
#include <agnocast/agnocast.hpp>
#include <cstdio>

#include "robot_messages.hpp"

int main() {
  agnocast::Node node{"hello_listener"};
  auto subscription = node.create_subscription<robot::Scan>(
      "/scan", agnocast::QoS{10}, [](const robot::Scan& scan) {
        std::printf("scan %llu: %zu ranges from %s\n", static_cast<unsigned long long>(scan.seq),
                    scan.ranges.size(), scan.frame_id.c_str());
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
}
