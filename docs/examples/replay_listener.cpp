// Prints each scan's number and the time since the previous one: run it
// while `agnocast-cli bag play` replays a recording of /scan to see the
// messages come back in order and with their original spacing.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>
#include <optional>

#include "robot_messages.hpp"

int main() {
  agnocast::Node node{"replay_listener"};
  std::optional<std::chrono::steady_clock::time_point> previous;
  auto subscription = node.create_subscription<robot::Scan>(
      "/scan", agnocast::QoS{10}, [&](const robot::Scan& scan) {
        const auto now = std::chrono::steady_clock::now();
        const double gap_ms =
            previous ? std::chrono::duration<double, std::milli>(now - *previous).count() : 0.0;
        previous = now;
        std::printf("scan %llu from %s, %zu ranges, %.1f ms after the previous one\n",
                    static_cast<unsigned long long>(scan.seq), scan.frame_id.c_str(),
                    scan.ranges.size(), gap_ms);
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
}
