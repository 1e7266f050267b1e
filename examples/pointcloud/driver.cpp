// agnocast-pointcloud-driver: the sensor end of the PointCloud2 pipeline.
// Publishes synthetic scans, filled in place in shared memory.
#include <CLI/CLI.hpp>
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>
#include <thread>

#include "cloud.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Publishes synthetic PointCloud2 scans."};
  std::string topic = "/points/raw";
  std::uint64_t count = 0;
  double rate = 10.0;
  std::uint32_t points = 10000;
  std::size_t depth = 10;
  app.add_option("--topic", topic, "topic to publish on");
  app.add_option("--count", count, "scans to publish (0: until SIGINT/SIGTERM)");
  app.add_option("--rate", rate, "scans per second")->check(CLI::PositiveNumber);
  app.add_option("--points", points, "points per scan")->check(CLI::Range(1u, 10'000'000u));
  app.add_option("--depth", depth, "QoS depth");
  CLI11_PARSE(app, argc, argv);

  try {
    agnocast::install_signal_handlers();
    agnocast::Node node{"pointcloud_driver"};
    auto publisher =
        node.create_publisher<sensor_msgs::msg::PointCloud2>(topic, agnocast::QoS{depth});
    const auto period = std::chrono::duration<double>(1.0 / rate);
    auto next = std::chrono::steady_clock::now();
    std::uint64_t published = 0;
    while (agnocast::ok() && (count == 0 || published < count)) {
      auto scan = publisher->borrow_loaned_message();
      pointcloud::fill_scan(*scan, published, points);
      publisher->publish(std::move(scan));
      ++published;
      next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
      std::this_thread::sleep_until(next);
    }
    std::fprintf(stderr, "agnocast-pointcloud-driver: published %llu scans on %s\n",
                 static_cast<unsigned long long>(published), topic.c_str());
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "agnocast-pointcloud-driver: %s\n", error.what());
    return 1;
  }
}
