// The bridge's sertype against Cyclone DDS's own idlc-generated C types, in one
// process (no kernel module needed): what the bridge writes with dds_writecdr
// an idlc reader takes with equal field values, and what an idlc writer sends
// the bridge's reader hands over as bytes that deserialize to equal values.
#include "cdr_sertype.hpp"

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <agnocast/cdr.hpp>
#include <cstdlib>
#include <cstring>
#include <geometry_msgs/msg/twist.hpp>
#include <new>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <string>
#include <vector>

#include "dds_domain.hpp"
#include "kernel/runtime.hpp"

extern "C" {
#include "bridge_test_pattern.h"
#include "ros2_messages.h"
}

namespace agnocast_bridge {
namespace {

constexpr std::uint32_t cloud_bytes = 64 * 1024;

class CdrSertypeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    static constexpr std::size_t pool_size = 8 << 20;
    auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
    agnocast::detail::Runtime::install_for_testing(region, pool_size);
    // This process only: no network traffic reaches or leaves the test.
    ::setenv("CYCLONEDDS_URI",
             "<General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
             "<AllowMulticast>false</AllowMulticast></General>",
             1);
  }

  void SetUp() override {
    domain_ = std::make_unique<DdsDomain>(static_cast<std::uint32_t>(::getpid() % 200));
    peer_ = dds_create_participant(domain_->domain_id(), nullptr, nullptr);
    ASSERT_GT(peer_, 0);
  }
  void TearDown() override { dds_delete(peer_); }

  dds_entity_t peer_endpoint(const char* topic, const dds_topic_descriptor_t* descriptor,
                             bool writer) {
    const dds_entity_t handle = dds_create_topic(peer_, descriptor, topic, nullptr, nullptr);
    EXPECT_GT(handle, 0);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 4);
    const dds_entity_t entity = writer ? dds_create_writer(peer_, handle, qos, nullptr)
                                       : dds_create_reader(peer_, handle, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(entity, 0);
    return entity;
  }

  static void wait_matched(dds_entity_t writer) {
    for (int i = 0; i < 500; ++i) {
      dds_publication_matched_status_t status{};
      dds_get_publication_matched_status(writer, &status);
      if (status.current_count > 0) return;
      dds_sleepfor(DDS_MSECS(10));
    }
    FAIL() << "writer never matched";
  }

  // Waits for one sample on an idlc-typed reader.
  static bool take_one(dds_entity_t reader, void** sample, dds_sample_info_t* info) {
    for (int i = 0; i < 500; ++i) {
      if (dds_take(reader, sample, info, 1, 1) == 1) return true;
      dds_sleepfor(DDS_MSECS(10));
    }
    return false;
  }

  // Waits for one sample's bytes on a bridge reader.
  static std::vector<std::uint8_t> take_bytes(dds_entity_t reader) {
    for (int i = 0; i < 500; ++i) {
      ddsi_serdata* serdata = nullptr;
      dds_sample_info_t info{};
      if (dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE) == 1) {
        const auto bytes = cdr_serdata_bytes(serdata);
        std::vector<std::uint8_t> copy(bytes.begin(), bytes.end());
        ddsi_serdata_unref(serdata);
        if (info.valid_data) return copy;
      }
      dds_sleepfor(DDS_MSECS(10));
    }
    return {};
  }

  std::unique_ptr<DdsDomain> domain_;
  dds_entity_t peer_ = 0;
};

TopicConfig topic(const char* name, const char* type) {
  return TopicConfig{name, type, Direction::to_dds, TopicQos{4, true, false}};
}

TEST_F(CdrSertypeTest, BridgeTwistReachesAnIdlcReader) {
  const auto config = topic("/cmd_vel", "geometry_msgs/msg/Twist");
  DdsTopic dds_topic = domain_->create_topic(config);
  DdsEntity writer = domain_->create_writer(dds_topic.entity.get(), config.qos);
  const dds_entity_t reader =
      peer_endpoint("rt/cmd_vel", &geometry_msgs_msg_dds__Twist__desc, false);
  wait_matched(writer.get());

  geometry_msgs::msg::Twist twist;
  twist.linear.x = twist_linear_x(7);
  twist.linear.y = twist_linear_y(7);
  twist.linear.z = twist_linear_z(7);
  twist.angular.x = twist_angular_x(7);
  twist.angular.y = twist_angular_y(7);
  twist.angular.z = twist_angular_z(7);
  ASSERT_EQ(dds_writecdr(writer.get(),
                         make_cdr_serdata(dds_topic.sertype, agnocast::cdr::serialize(twist))),
            DDS_RETCODE_OK);

  void* sample = nullptr;
  dds_sample_info_t info{};
  ASSERT_TRUE(take_one(reader, &sample, &info));
  const auto* received = static_cast<const geometry_msgs_msg_dds__Twist_*>(sample);
  EXPECT_EQ(received->linear.x, twist_linear_x(7));
  EXPECT_EQ(received->linear.y, twist_linear_y(7));
  EXPECT_EQ(received->linear.z, twist_linear_z(7));
  EXPECT_EQ(received->angular.x, twist_angular_x(7));
  EXPECT_EQ(received->angular.y, twist_angular_y(7));
  EXPECT_EQ(received->angular.z, twist_angular_z(7));
  dds_return_loan(reader, &sample, 1);
}

TEST_F(CdrSertypeTest, IdlcPointCloud2ReachesTheBridgeIntact) {
  auto config = topic("/points", "sensor_msgs/msg/PointCloud2");
  DdsTopic dds_topic = domain_->create_topic(config);
  DdsEntity reader = domain_->create_reader(dds_topic.entity.get(), config.qos);
  const dds_entity_t writer =
      peer_endpoint("rt/points", &sensor_msgs_msg_dds__PointCloud2__desc, true);
  wait_matched(writer);

  sensor_msgs_msg_dds__PointField_ fields[4];
  for (std::uint32_t f = 0; f < 4; ++f) {
    fields[f] = {const_cast<char*>(cloud_field_names[f]), 4 * f, 7, 1};
  }
  std::vector<std::uint8_t> data(cloud_bytes);
  for (std::uint32_t k = 0; k < cloud_bytes; ++k) data[k] = cloud_byte(3, k);
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  cloud.header.stamp = {3, CLOUD_NANOSEC};
  cloud.header.frame_id = const_cast<char*>(CLOUD_FRAME_ID);
  cloud.height = 1;
  cloud.width = cloud_bytes / CLOUD_POINT_STEP;
  cloud.fields = {4, 4, fields, false};
  cloud.point_step = CLOUD_POINT_STEP;
  cloud.row_step = cloud_bytes;
  cloud.data = {cloud_bytes, cloud_bytes, data.data(), false};
  cloud.is_dense = true;
  ASSERT_EQ(dds_write(writer, &cloud), DDS_RETCODE_OK);

  const std::vector<std::uint8_t> bytes = take_bytes(reader.get());
  ASSERT_FALSE(bytes.empty());
  sensor_msgs::msg::PointCloud2 received;
  agnocast::cdr::deserialize(bytes, received);
  EXPECT_EQ(received.header.stamp.sec, 3);
  EXPECT_EQ(received.header.stamp.nanosec, CLOUD_NANOSEC);
  EXPECT_EQ(received.header.frame_id, CLOUD_FRAME_ID);
  EXPECT_EQ(received.width, cloud_bytes / CLOUD_POINT_STEP);
  ASSERT_EQ(received.fields.size(), 4u);
  EXPECT_EQ(received.fields[3].name, "intensity");
  EXPECT_EQ(received.fields[3].offset, 12u);
  EXPECT_TRUE(received.is_dense);
  ASSERT_EQ(received.data.size(), cloud_bytes);
  EXPECT_EQ(std::memcmp(received.data.data(), data.data(), cloud_bytes), 0);
  // Byte for byte what the bridge itself writes for this message, padding included.
  ddsi_serdata* own = make_cdr_serdata(dds_topic.sertype, agnocast::cdr::serialize(received));
  const auto own_bytes = cdr_serdata_bytes(own);
  EXPECT_EQ(std::vector<std::uint8_t>(own_bytes.begin(), own_bytes.end()), bytes);
  release_serdata(own);
}

TEST_F(CdrSertypeTest, BridgeReaderIgnoresItsOwnWriter) {
  auto config = topic("/loop", "geometry_msgs/msg/Twist");
  DdsTopic dds_topic = domain_->create_topic(config);
  DdsEntity writer = domain_->create_writer(dds_topic.entity.get(), config.qos);
  DdsEntity reader = domain_->create_reader(dds_topic.entity.get(), config.qos);
  const dds_entity_t peer_reader =
      peer_endpoint("rt/loop", &geometry_msgs_msg_dds__Twist__desc, false);
  wait_matched(writer.get());

  geometry_msgs::msg::Twist twist;
  twist.linear.x = 1;
  ASSERT_EQ(dds_writecdr(writer.get(),
                         make_cdr_serdata(dds_topic.sertype, agnocast::cdr::serialize(twist))),
            DDS_RETCODE_OK);
  void* sample = nullptr;
  dds_sample_info_t info{};
  ASSERT_TRUE(take_one(peer_reader, &sample, &info));  // it was sent
  dds_return_loan(peer_reader, &sample, 1);
  ddsi_serdata* own = nullptr;
  EXPECT_EQ(dds_takecdr(reader.get(), &own, 1, &info, DDS_ANY_STATE), 0);  // but not read back
}

}  // namespace
}  // namespace agnocast_bridge
