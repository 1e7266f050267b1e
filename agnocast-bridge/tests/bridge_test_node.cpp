// The agnocast side of the bridge tests: publishes or receives the messages of
// bridge_test_pattern.h on an agnocast topic and checks every field.
//
//   agnocast-bridge-test-node publish-twist TOPIC COUNT RATE_HZ
//   agnocast-bridge-test-node receive-twist TOPIC COUNT TIMEOUT_S QUIET_S
//   agnocast-bridge-test-node publish-cloud TOPIC BYTES COUNT
//   agnocast-bridge-test-node receive-cloud TOPIC BYTES COUNT TIMEOUT_S
//
// A publisher waits for a subscriber (the bridge) first. A receiver prints
// "@ready" once subscribed and exits 0 only when each of COUNT messages came
// exactly once with the values sent (receive-twist: and nothing more within
// QUIET_S seconds after the last).
#include <agnocast/agnocast.hpp>
#include <agnocast/inspect.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <geometry_msgs/msg/twist.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <string>
#include <thread>
#include <vector>

extern "C" {
#include "bridge_test_pattern.h"
}

namespace {

using Clock = std::chrono::steady_clock;
using geometry_msgs::msg::Twist;
using sensor_msgs::msg::PointCloud2;

std::chrono::nanoseconds seconds(double value) {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(value * 1e9));
}

bool wait_for_subscriber(const std::string& topic) {
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (Clock::now() < deadline) {
    const auto info = agnocast::topic_info(topic);
    if (info && !info->subscribers.empty()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::fprintf(stderr, "agnocast-bridge-test-node: no subscriber on %s\n", topic.c_str());
  return false;
}

int publish_twist(const std::string& topic, std::uint32_t count, double rate) {
  agnocast::Node node("bridge_test_publisher");
  auto publisher = node.create_publisher<Twist>(topic, agnocast::QoS(100));
  if (!wait_for_subscriber(topic)) return 1;
  auto next = Clock::now();
  for (std::uint32_t i = 0; i < count; ++i) {
    auto message = publisher->borrow_loaned_message();
    message->linear.x = twist_linear_x(i);
    message->linear.y = twist_linear_y(i);
    message->linear.z = twist_linear_z(i);
    message->angular.x = twist_angular_x(i);
    message->angular.y = twist_angular_y(i);
    message->angular.z = twist_angular_z(i);
    publisher->publish(std::move(message));
    next += seconds(1.0 / rate);
    std::this_thread::sleep_until(next);
  }
  std::printf("agnocast-bridge-test-node: published %u Twist on %s\n", count, topic.c_str());
  return 0;
}

bool twist_matches(const Twist& t, std::uint32_t i) {
  return t.linear.x == twist_linear_x(i) && t.linear.y == twist_linear_y(i) &&
         t.linear.z == twist_linear_z(i) && t.angular.x == twist_angular_x(i) &&
         t.angular.y == twist_angular_y(i) && t.angular.z == twist_angular_z(i);
}

int receive_twist(const std::string& topic, std::uint32_t count, double timeout_s, double quiet_s) {
  agnocast::Node node("bridge_test_receiver");
  std::vector<bool> seen(count, false);
  std::uint32_t distinct = 0, duplicates = 0, wrong = 0, extra = 0;
  auto subscription = node.create_subscription<Twist>(
      topic, agnocast::QoS(100), [&](const agnocast::ipc_shared_ptr<const Twist>& message) {
        const double x = message->linear.x;
        const auto i = static_cast<std::uint32_t>(x);
        if (x < 0 || static_cast<double>(i) != x || i >= count) {
          ++extra;
        } else if (!twist_matches(*message, i)) {
          ++wrong;
        } else if (seen[i]) {
          ++duplicates;
        } else {
          seen[i] = true;
          ++distinct;
        }
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::printf("@ready\n");
  std::fflush(stdout);
  const auto deadline = Clock::now() + seconds(timeout_s);
  Clock::time_point quiet_until{};
  for (;;) {
    const auto now = Clock::now();
    if (quiet_until == Clock::time_point{} && distinct == count)
      quiet_until = now + seconds(quiet_s);
    if (quiet_until != Clock::time_point{} ? now >= quiet_until : now >= deadline) break;
    executor.spin_once(std::chrono::milliseconds(50));
  }
  std::printf(
      "agnocast-bridge-test-node: %s: %u of %u Twist, %u duplicates, %u with wrong values, %u "
      "unexpected\n",
      topic.c_str(), distinct, count, duplicates, wrong, extra);
  return distinct == count && duplicates == 0 && wrong == 0 && extra == 0 ? 0 : 1;
}

int publish_cloud(const std::string& topic, std::uint32_t bytes, std::uint32_t count) {
  agnocast::Node node("bridge_test_publisher");
  auto publisher = node.create_publisher<PointCloud2>(topic, agnocast::QoS(4));
  if (!wait_for_subscriber(topic)) return 1;
  for (std::uint32_t i = 0; i < count; ++i) {
    auto cloud = publisher->borrow_loaned_message();
    cloud->header.stamp.sec = static_cast<std::int32_t>(i);
    cloud->header.stamp.nanosec = CLOUD_NANOSEC;
    cloud->header.frame_id = CLOUD_FRAME_ID;
    cloud->height = 1;
    cloud->width = bytes / CLOUD_POINT_STEP;
    for (std::uint32_t f = 0; f < 4; ++f) {
      auto& field = cloud->fields.emplace_back();
      field.name = cloud_field_names[f];
      field.offset = 4 * f;
      field.datatype = sensor_msgs::msg::PointField::FLOAT32;
      field.count = 1;
    }
    cloud->is_bigendian = false;
    cloud->point_step = CLOUD_POINT_STEP;
    cloud->row_step = bytes;
    cloud->data.resize(bytes);
    for (std::uint32_t k = 0; k < bytes; ++k) cloud->data[k] = cloud_byte(i, k);
    cloud->is_dense = true;
    publisher->publish(std::move(cloud));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  std::printf("agnocast-bridge-test-node: published %u PointCloud2 of %u bytes on %s\n", count,
              bytes, topic.c_str());
  return 0;
}

bool cloud_matches(const PointCloud2& c, std::uint32_t bytes) {
  const auto i = static_cast<std::uint32_t>(c.header.stamp.sec);
  if (c.header.stamp.nanosec != CLOUD_NANOSEC || c.header.frame_id != CLOUD_FRAME_ID ||
      c.height != 1 || c.width != bytes / CLOUD_POINT_STEP || c.fields.size() != 4 ||
      c.is_bigendian || c.point_step != CLOUD_POINT_STEP || c.row_step != bytes ||
      c.data.size() != bytes || !c.is_dense) {
    return false;
  }
  for (std::uint32_t f = 0; f < 4; ++f) {
    const auto& field = c.fields[f];
    if (field.name != cloud_field_names[f] || field.offset != 4 * f || field.datatype != 7 ||
        field.count != 1) {
      return false;
    }
  }
  for (std::uint32_t k = 0; k < bytes; ++k) {
    if (c.data[k] != cloud_byte(i, k)) return false;
  }
  return true;
}

int receive_cloud(const std::string& topic, std::uint32_t bytes, std::uint32_t count,
                  double timeout_s) {
  agnocast::Node node("bridge_test_receiver");
  std::uint32_t intact = 0, damaged = 0;
  auto subscription = node.create_subscription<PointCloud2>(
      topic, agnocast::QoS(4), [&](const agnocast::ipc_shared_ptr<const PointCloud2>& cloud) {
        ++(cloud_matches(*cloud, bytes) ? intact : damaged);
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::printf("@ready\n");
  std::fflush(stdout);
  const auto deadline = Clock::now() + seconds(timeout_s);
  while (intact + damaged < count && Clock::now() < deadline) {
    executor.spin_once(std::chrono::milliseconds(50));
  }
  std::printf(
      "agnocast-bridge-test-node: %s: %u of %u PointCloud2 of %u bytes intact, %u damaged\n",
      topic.c_str(), intact, count, bytes, damaged);
  return intact == count && damaged == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 4 && args[0] == "publish-twist") {
    return publish_twist(args[1], std::stoul(args[2]), std::stod(args[3]));
  }
  if (args.size() == 5 && args[0] == "receive-twist") {
    return receive_twist(args[1], std::stoul(args[2]), std::stod(args[3]), std::stod(args[4]));
  }
  if (args.size() == 4 && args[0] == "publish-cloud") {
    return publish_cloud(args[1], std::stoul(args[2]), std::stoul(args[3]));
  }
  if (args.size() == 5 && args[0] == "receive-cloud") {
    return receive_cloud(args[1], std::stoul(args[2]), std::stoul(args[3]), std::stod(args[4]));
  }
  std::fprintf(stderr,
               "usage: agnocast-bridge-test-node publish-twist|receive-twist|"
               "publish-cloud|receive-cloud TOPIC ...\n");
  return 2;
}
