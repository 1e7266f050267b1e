// agnocast-pointcloud-consumer: the end of the PointCloud2 pipeline. Checks
// every point of every filtered scan in place and prints a summary.
#include <CLI/CLI.hpp>
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>

#include "cloud.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Receives filtered PointCloud2 scans and checks their points' ranges."};
  std::string topic = "/points/filtered";
  std::uint64_t count = 0;
  float min_range = 2.0F;
  float max_range = 6.0F;
  std::size_t depth = 10;
  double timeout = 0;
  app.add_option("--topic", topic, "topic to subscribe to");
  app.add_option("--count", count, "exit after this many scans (0: never)");
  app.add_option("--min-range", min_range, "metres: no point may be closer");
  app.add_option("--max-range", max_range, "metres: no point may be farther");
  app.add_option("--depth", depth, "QoS depth");
  app.add_option("--timeout", timeout, "exit 1 after this many seconds (0: never)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  std::uint64_t scans = 0;
  std::uint64_t points = 0;
  std::uint64_t out_of_range = 0;
  try {
    agnocast::install_signal_handlers();
    agnocast::Node node{"pointcloud_consumer"};
    using sensor_msgs::msg::PointCloud2;
    auto subscription = node.create_subscription<PointCloud2>(
        topic, agnocast::QoS{depth}, [&](const agnocast::ipc_shared_ptr<const PointCloud2>& scan) {
          const std::size_t n = pointcloud::point_count(*scan);
          for (std::size_t i = 0; i < n; ++i) {
            const float range = pointcloud::point_range(*scan, i);
            // The filter kept [min, max]; allow float rounding of the recomputed range.
            if (range < min_range - 1e-4F || range > max_range + 1e-4F) ++out_of_range;
          }
          points += n;
          ++scans;
        });
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    using Clock = std::chrono::steady_clock;
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(timeout));
    while (agnocast::ok() && (count == 0 || scans < count)) {
      if (timeout > 0 && Clock::now() >= deadline) break;
      executor.spin_once(std::chrono::milliseconds(100));
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "agnocast-pointcloud-consumer: %s\n", error.what());
    return 1;
  }
  std::printf("{\"scans\":%llu,\"points\":%llu,\"out_of_range\":%llu}\n",
              static_cast<unsigned long long>(scans), static_cast<unsigned long long>(points),
              static_cast<unsigned long long>(out_of_range));
  if (out_of_range > 0 || (count > 0 && scans < count)) return 1;
  return 0;
}
