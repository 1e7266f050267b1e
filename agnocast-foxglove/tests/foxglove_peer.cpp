// The agnocast side of the Foxglove client check (foxglove-vm-test):
//   foxglove_peer sensors RECEIVED  publishes /fg_points (PointCloud2) and
//       /fg_chatter (std_msgs/String) every 50 ms, values derived from a counter
//       n as check-foxglove.mjs expects; appends every std_msgs/String taken on
//       /fg_from_client to RECEIVED, one line each.
//   foxglove_peer fast WINDOWS  publishes a 16 KiB PointCloud2 on /fg_fast at
//       1 kHz and appends, every 500 ms, one JSON line: messages published so
//       far and the publish() call's p50 and maximum in that window (µs).
// Runs until SIGTERM.
#include <agnocast/agnocast.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <std_msgs/msg/string.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace std::chrono_literals;

void fill_cloud(sensor_msgs::msg::PointCloud2& cloud, std::uint32_t n, std::size_t points) {
  cloud.header.frame_id = "lidar";
  cloud.header.stamp.sec = static_cast<std::int32_t>(n);
  cloud.header.stamp.nanosec = 500;
  sensor_msgs::msg::PointField x;
  x.name = "x";
  x.offset = 0;
  x.datatype = 7;  // FLOAT32
  x.count = 1;
  cloud.fields.push_back(x);
  cloud.height = 1;
  cloud.width = static_cast<std::uint32_t>(points);
  cloud.point_step = 4;
  cloud.row_step = static_cast<std::uint32_t>(4 * points);
  cloud.is_dense = true;
  cloud.data.resize(4 * points);
  for (std::size_t i = 0; i < std::min<std::size_t>(points, 3); ++i) {
    const float value = static_cast<float>(n) + 0.5F * static_cast<float>(i);
    std::memcpy(cloud.data.data() + 4 * i, &value, 4);
  }
}

int sensors(const std::string& received_path) {
  agnocast::Node node("foxglove_peer");
  auto points =
      node.create_publisher<sensor_msgs::msg::PointCloud2>("/fg_points", agnocast::QoS(10));
  auto chatter = node.create_publisher<std_msgs::msg::String>("/fg_chatter", agnocast::QoS(10));
  std::ofstream received(received_path, std::ios::app);
  auto from_client = node.create_subscription<std_msgs::msg::String>(
      "/fg_from_client", agnocast::QoS(100),
      [&](const std_msgs::msg::String& message) { received << message.data << std::endl; });
  std::uint32_t n = 0;
  auto timer = node.create_wall_timer(50ms, [&] {
    ++n;
    auto cloud = points->borrow_loaned_message();
    fill_cloud(*cloud, n, 3);
    points->publish(std::move(cloud));
    auto text = chatter->borrow_loaned_message();
    text->data = "hello " + std::to_string(n);
    chatter->publish(std::move(text));
  });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();
  return 0;
}

int fast(const std::string& windows_path) {
  agnocast::install_signal_handlers();
  agnocast::Node node("foxglove_fast_peer");
  auto points = node.create_publisher<sensor_msgs::msg::PointCloud2>("/fg_fast", agnocast::QoS(10));
  std::ofstream windows(windows_path, std::ios::app);
  std::vector<double> calls_us;
  std::uint64_t published = 0;
  std::uint32_t n = 0;
  auto next = std::chrono::steady_clock::now();
  auto window_end = next + 500ms;
  while (agnocast::ok()) {
    auto cloud = points->borrow_loaned_message();
    fill_cloud(*cloud, ++n, 4096);  // 16 KiB of points
    const auto before = std::chrono::steady_clock::now();
    points->publish(std::move(cloud));
    calls_us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - before)
            .count());
    ++published;
    next += 1ms;
    const auto now = std::chrono::steady_clock::now();
    if (next < now - 10ms) next = now;  // fell behind: no burst to catch up
    if (now >= window_end && !calls_us.empty()) {
      std::sort(calls_us.begin(), calls_us.end());
      char line[160];
      std::snprintf(line, sizeof line, "{\"published\":%llu,\"p50_us\":%.1f,\"max_us\":%.1f}\n",
                    static_cast<unsigned long long>(published), calls_us[calls_us.size() / 2],
                    calls_us.back());
      windows << line << std::flush;
      calls_us.clear();
      window_end = now + 500ms;
    }
    std::this_thread::sleep_until(next);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "sensors") return sensors(argv[2]);
  if (argc == 3 && std::string(argv[1]) == "fast") return fast(argv[2]);
  std::fprintf(stderr, "usage: foxglove_peer sensors RECEIVED | fast WINDOWS\n");
  return 2;
}
