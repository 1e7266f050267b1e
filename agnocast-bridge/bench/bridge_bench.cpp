// The agnocast side of the bridge benchmark: sensor_msgs/PointCloud2 whose
// data holds the payload, through the bridge to DDS and back.
//
//   agnocast-bridge-bench ping BYTES COUNT     round trips /bench/ping -> DDS echo -> /bench/pong
//   agnocast-bridge-bench flood BYTES SECONDS  publishes /bench/tput as fast as it can
//
// Prints the same lines as agnocast-bridge-bench-peer ("rtt ..." / "sent ...").
#include <agnocast/agnocast.hpp>
#include <agnocast/inspect.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
using sensor_msgs::msg::PointCloud2;

void wait_for_subscriber(const std::string& topic) {
  for (int i = 0; i < 3000; ++i) {
    const auto info = agnocast::topic_info(topic);
    if (info && !info->subscribers.empty()) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void fill(PointCloud2& cloud, std::uint32_t bytes, std::int32_t sequence) {
  cloud.header.stamp.sec = sequence;
  cloud.height = 1;
  cloud.width = bytes;
  cloud.point_step = 1;
  cloud.row_step = bytes;
  cloud.data.resize(bytes);
}

int ping(std::uint32_t bytes, std::uint32_t count) {
  agnocast::Node node("bridge_bench");
  auto publisher = node.create_publisher<PointCloud2>("/bench/ping", agnocast::QoS(16));
  std::int32_t last_pong = -1;
  auto subscription = node.create_subscription<PointCloud2>(
      "/bench/pong", agnocast::QoS(16),
      [&](const agnocast::ipc_shared_ptr<const PointCloud2>& cloud) {
        last_pong = cloud->header.stamp.sec;
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  wait_for_subscriber("/bench/ping");
  std::this_thread::sleep_for(std::chrono::seconds(1));  // DDS discovery on both legs
  const std::uint32_t warmup = count / 10 + 1;
  std::vector<double> rtt_us;
  for (std::uint32_t i = 0; i < count + warmup; ++i) {
    auto cloud = publisher->borrow_loaned_message();
    fill(*cloud, bytes, static_cast<std::int32_t>(i));
    const auto sent = Clock::now();
    publisher->publish(std::move(cloud));
    while (last_pong != static_cast<std::int32_t>(i) &&
           Clock::now() - sent < std::chrono::seconds(5)) {
      executor.spin_once(std::chrono::milliseconds(100));
    }
    if (last_pong == static_cast<std::int32_t>(i) && i >= warmup) {
      rtt_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - sent).count());
    }
  }
  if (rtt_us.empty()) {
    std::fprintf(stderr, "agnocast-bridge-bench: no round trip completed\n");
    return 1;
  }
  std::sort(rtt_us.begin(), rtt_us.end());
  const std::size_t n = rtt_us.size();
  std::printf("rtt %u n %zu median_us %.1f p90_us %.1f p99_us %.1f\n", bytes, n, rtt_us[n / 2],
              rtt_us[n * 9 / 10], rtt_us[n * 99 / 100]);
  return 0;
}

int flood(std::uint32_t bytes, double seconds) {
  agnocast::Node node("bridge_bench");
  auto publisher = node.create_publisher<PointCloud2>("/bench/tput", agnocast::QoS(16));
  wait_for_subscriber("/bench/tput");
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  std::uint32_t sent = 0;
  while (Clock::now() < end) {
    auto cloud = publisher->borrow_loaned_message();
    fill(*cloud, bytes, static_cast<std::int32_t>(sent));
    publisher->publish(std::move(cloud));
    ++sent;
  }
  std::printf("sent %u %u\n", bytes, sent);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 3 && args[0] == "ping") return ping(std::stoul(args[1]), std::stoul(args[2]));
  if (args.size() == 3 && args[0] == "flood") return flood(std::stoul(args[1]), std::stod(args[2]));
  std::fprintf(stderr, "usage: agnocast-bridge-bench ping BYTES COUNT | flood BYTES SECONDS\n");
  return 2;
}
