#include "cloud.hpp"

#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>

namespace pointcloud {
namespace {

struct Point {
  float x, y, z, intensity;
};
static_assert(sizeof(Point) == point_step);

Point load(const sensor_msgs::msg::PointCloud2& cloud, std::size_t index) {
  Point point;
  std::memcpy(&point, cloud.data.data() + index * cloud.point_step, sizeof(point));
  return point;
}

}  // namespace

void set_layout(sensor_msgs::msg::PointCloud2& cloud, std::uint32_t points) {
  using sensor_msgs::msg::PointField;
  cloud.fields.clear();
  std::uint32_t offset = 0;
  for (const char* name : {"x", "y", "z", "intensity"}) {
    cloud.fields.push_back({name, offset, PointField::FLOAT32, 1});
    offset += sizeof(float);
  }
  cloud.height = 1;
  cloud.width = points;
  cloud.point_step = point_step;
  cloud.row_step = point_step * points;
  cloud.is_bigendian = false;
  cloud.is_dense = true;
  cloud.data.resize(cloud.row_step);
}

void fill_scan(sensor_msgs::msg::PointCloud2& cloud, std::uint64_t seq, std::uint32_t points) {
  set_layout(cloud, points);
  cloud.header.frame_id = "lidar";
  cloud.header.stamp.sec = static_cast<std::int32_t>(seq / 10);
  cloud.header.stamp.nanosec = static_cast<std::uint32_t>(seq % 10) * 100'000'000u;
  const double turn = 0.01 * static_cast<double>(seq);
  for (std::uint32_t i = 0; i < points; ++i) {
    const auto radius = static_cast<float>(1 + i % 10);
    const double angle = turn + 2 * std::numbers::pi * i / points;
    const Point point{radius * static_cast<float>(std::cos(angle)),
                      radius * static_cast<float>(std::sin(angle)),
                      0.1F * static_cast<float>(i % 3), radius};
    std::memcpy(cloud.data.data() + std::size_t{i} * point_step, &point, sizeof(point));
  }
}

float point_range(const sensor_msgs::msg::PointCloud2& cloud, std::size_t index) {
  const Point point = load(cloud, index);
  return std::hypot(point.x, point.y);
}

std::size_t point_count(const sensor_msgs::msg::PointCloud2& cloud) {
  return cloud.point_step == 0 ? 0 : cloud.data.size() / cloud.point_step;
}

std::size_t filter_by_range(const sensor_msgs::msg::PointCloud2& in, float min_range,
                            float max_range, sensor_msgs::msg::PointCloud2& out) {
  if (in.point_step != point_step) {
    throw std::invalid_argument("expected x, y, z, intensity float32 points (point_step 16)");
  }
  const std::size_t total = point_count(in);
  std::size_t kept = 0;
  set_layout(out, static_cast<std::uint32_t>(total));  // room for all, trimmed below
  out.header = in.header;
  for (std::size_t i = 0; i < total; ++i) {
    const float range = point_range(in, i);
    if (range < min_range || range > max_range) continue;
    std::memcpy(out.data.data() + kept * point_step, in.data.data() + i * in.point_step,
                point_step);
    ++kept;
  }
  out.width = static_cast<std::uint32_t>(kept);
  out.row_step = static_cast<std::uint32_t>(kept * point_step);
  out.data.resize(out.row_step);
  return kept;
}

}  // namespace pointcloud
