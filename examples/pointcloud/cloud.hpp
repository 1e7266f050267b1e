// The point clouds of the PointCloud2 pipeline example: x, y, z, intensity as
// float32, one row. Shared by the driver, the filter and the consumer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <sensor_msgs/msg/point_cloud2.hpp>

namespace pointcloud {

inline constexpr std::uint32_t point_step = 4 * sizeof(float);

// Gives `cloud` the x/y/z/intensity layout and room for `points` points.
void set_layout(sensor_msgs::msg::PointCloud2& cloud, std::uint32_t points);

// A synthetic scan: `points` points on rings of radius 1 to 10 m, turning with
// `seq`; each point's intensity is its radius.
void fill_scan(sensor_msgs::msg::PointCloud2& cloud, std::uint64_t seq, std::uint32_t points);

// The horizontal distance of point `index` from the sensor.
float point_range(const sensor_msgs::msg::PointCloud2& cloud, std::size_t index);

std::size_t point_count(const sensor_msgs::msg::PointCloud2& cloud);

// Copies into `out` (same header and layout) the points of `in` whose range is
// within [min_range, max_range]; returns how many.
std::size_t filter_by_range(const sensor_msgs::msg::PointCloud2& in, float min_range,
                            float max_range, sensor_msgs::msg::PointCloud2& out);

}  // namespace pointcloud
