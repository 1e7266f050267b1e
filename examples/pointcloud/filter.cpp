// agnocast-pointcloud-filter: the middle of the PointCloud2 pipeline. Reads each
// scan in place (zero copy) and publishes the points within a range band.
#include <CLI/CLI.hpp>
#include <agnocast/agnocast.hpp>
#include <cstdio>

#include "cloud.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Keeps the points of each PointCloud2 whose range is within a band."};
  std::string input = "/points/raw";
  std::string output = "/points/filtered";
  float min_range = 2.0F;
  float max_range = 6.0F;
  std::size_t depth = 10;
  app.add_option("--input", input, "topic to read scans from");
  app.add_option("--output", output, "topic to publish filtered scans on");
  app.add_option("--min-range", min_range, "metres");
  app.add_option("--max-range", max_range, "metres");
  app.add_option("--depth", depth, "QoS depth on both topics");
  CLI11_PARSE(app, argc, argv);

  try {
    agnocast::install_signal_handlers();
    agnocast::Node node{"pointcloud_filter"};
    using sensor_msgs::msg::PointCloud2;
    auto publisher = node.create_publisher<PointCloud2>(output, agnocast::QoS{depth});
    std::uint64_t filtered = 0;
    auto subscription = node.create_subscription<PointCloud2>(
        input, agnocast::QoS{depth}, [&](const agnocast::ipc_shared_ptr<const PointCloud2>& scan) {
          auto out = publisher->borrow_loaned_message();
          pointcloud::filter_by_range(*scan, min_range, max_range, *out);
          publisher->publish(std::move(out));
          ++filtered;
        });
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    executor.spin();  // until SIGINT/SIGTERM
    std::fprintf(stderr, "agnocast-pointcloud-filter: filtered %llu scans\n",
                 static_cast<unsigned long long>(filtered));
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "agnocast-pointcloud-filter: %s\n", error.what());
    return 1;
  }
}
