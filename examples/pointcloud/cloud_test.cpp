#include "cloud.hpp"

#include <gtest/gtest.h>

#include "kernel/runtime.hpp"

namespace pointcloud {
namespace {

class Cloud : public ::testing::Test {
 protected:
  void SetUp() override {
    static constexpr std::size_t pool_size = 4 << 20;
    // Left to the leaked test runtime, like every test pool.
    auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
    agnocast::detail::Runtime::install_for_testing(region, pool_size);
  }
};

TEST_F(Cloud, ScanHasRingsOfOneToTenMetres) {
  sensor_msgs::msg::PointCloud2 scan;
  fill_scan(scan, 7, 100);
  ASSERT_EQ(point_count(scan), 100u);
  EXPECT_EQ(scan.width, 100u);
  EXPECT_EQ(scan.row_step, 100 * point_step);
  EXPECT_EQ(scan.fields.size(), 4u);
  EXPECT_EQ(scan.fields[3].name, "intensity");
  for (std::size_t i = 0; i < 100; ++i) EXPECT_NEAR(point_range(scan, i), 1 + i % 10, 1e-4) << i;
}

TEST_F(Cloud, FilterKeepsTheBandOnly) {
  sensor_msgs::msg::PointCloud2 scan;
  fill_scan(scan, 0, 100);
  sensor_msgs::msg::PointCloud2 kept;
  // Radii 2..6 of every 10: half of the points.
  EXPECT_EQ(filter_by_range(scan, 1.5F, 6.5F, kept), 50u);
  EXPECT_EQ(point_count(kept), 50u);
  EXPECT_EQ(kept.width, 50u);
  EXPECT_EQ(kept.header.frame_id, "lidar");
  for (std::size_t i = 0; i < 50; ++i) {
    EXPECT_GE(point_range(kept, i), 1.5F);
    EXPECT_LE(point_range(kept, i), 6.5F);
  }
}

TEST_F(Cloud, FilterRefusesOtherLayouts) {
  sensor_msgs::msg::PointCloud2 scan;
  fill_scan(scan, 0, 10);
  scan.point_step = 12;
  sensor_msgs::msg::PointCloud2 kept;
  EXPECT_THROW(filter_by_range(scan, 0, 10, kept), std::invalid_argument);
}

}  // namespace
}  // namespace pointcloud
