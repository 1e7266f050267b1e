// Publishes a struct written with std::string and std::vector, unchanged, ten
// times a second; built linked with agnocast::heaphook (or run it with
// LD_PRELOAD=libagnocast_heaphook.so).
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace lidar {

struct Point {
  float x = 0, y = 0, z = 0;
};

// As it was written before agnocast: standard containers only.
struct Cloud {
  std::uint64_t seq = 0;
  std::string frame_id;
  std::vector<Point> points;
};

}  // namespace lidar

// The opt-in: the fields, as with AGNOCAST_MESSAGE; the struct stays as it is.
AGNOCAST_HEAP_MESSAGE(lidar::Cloud, "lidar/msg/Cloud", seq, frame_id, points);

int main() {
  agnocast::Node node{"existing_types"};
  // Throws agnocast::Error, saying how to enable it, when the hook is not active.
  auto publisher = node.create_publisher<lidar::Cloud>("/cloud", agnocast::QoS{10});
  std::uint64_t seq = 0;
  auto timer = node.create_wall_timer(std::chrono::milliseconds{100}, [&] {
    auto cloud = publisher->borrow_loaned_message();  // this thread now allocates in the pool
    cloud->seq = seq++;
    cloud->frame_id = "lidar_front_left";
    for (int i = 0; i < 1000; ++i) cloud->points.push_back({0.01F * i, 0, 1});
    publisher->publish(std::move(cloud));  // and privately again from here
  });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
}
