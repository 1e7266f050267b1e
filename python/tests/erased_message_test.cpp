// The generic accessor against the C++ types it stands in for: a message
// built, filled and destroyed through its schema alone must be the message
// the generated C++ code reads, and the other way round. Pool memory comes
// from the library's test runtime, no kernel needed.
#include "erased_message.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <geometry_msgs/msg/vector3.hpp>
#include <new>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <std_msgs/msg/string.hpp>
#include <string>
#include <wheel_msgs/msg/wheel.hpp>

#include "agnocast/allocator.hpp"
#include "kernel/fake_runtime.hpp"

namespace agnocast::python {
namespace {

template <class T>
ErasedSchema schema_for() {
  const auto blob = agnocast::schema_of<T>();
  return ErasedSchema(std::vector<std::uint8_t>(blob.begin(), blob.end()));
}

const SchemaField& field(const ErasedSchema& schema, std::uint16_t type, const char* name) {
  const SchemaField* found = schema.field(type, name);
  EXPECT_NE(found, nullptr) << name;
  return *found;
}

template <class T>
T* raw_message() {
  return static_cast<T*>(detail::pool_allocate(sizeof(T), alignof(T)));
}

class ErasedMessageTest : public detail::FakeRuntimeTest {};

TEST_F(ErasedMessageTest, SchemaNamesTheGeneratedTypeAndItsLayout) {
  const ErasedSchema schema = schema_for<sensor_msgs::msg::PointCloud2>();
  const SchemaType& type = schema.type(0);
  EXPECT_EQ(type.name, "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(type.hash, message_traits<sensor_msgs::msg::PointCloud2>::type_hash);
  EXPECT_EQ(type.size, sizeof(sensor_msgs::msg::PointCloud2));
  EXPECT_EQ(type.align, alignof(sensor_msgs::msg::PointCloud2));
  EXPECT_EQ(field(schema, 0, "data").offset, offsetof(sensor_msgs::msg::PointCloud2, data));
  EXPECT_EQ(field(schema, 0, "is_dense").offset, offsetof(sensor_msgs::msg::PointCloud2, is_dense));
  EXPECT_EQ(schema.field(0, "no_such_field"), nullptr);
}

TEST_F(ErasedMessageTest, BuiltThroughTheSchemaReadsAsTheCppType) {
  const ErasedSchema schema = schema_for<wheel_msgs::msg::Wheel>();
  const ErasedOps ops(schema);
  auto* wheel = raw_message<wheel_msgs::msg::Wheel>();
  ops.construct(wheel, 0);
  auto* bytes = reinterpret_cast<std::byte*>(wheel);

  const SchemaField& header = field(schema, 0, "header");
  const SchemaField& frame_id = field(schema, header.nested, "frame_id");
  ops.assign_string(bytes + header.offset + frame_id.offset,
                    "a frame id longer than sixteen bytes");
  ops.assign_string(bytes + field(schema, 0, "name").offset, "fl");

  const SchemaField& speeds = field(schema, 0, "speeds");
  ops.resize_sequence(bytes + speeds.offset, speeds, 3);
  const VectorSpan speed_span = ops.sequence(bytes + speeds.offset, speeds);
  ASSERT_EQ(speed_span.count, 3u);
  const double values[3] = {1.5, 2.5, 3.5};
  std::memcpy(speed_span.data, values, sizeof(values));
  ops.resize_sequence(bytes + speeds.offset, speeds, 1000);  // grows: moves, keeps the first 3

  const SchemaField& forces = field(schema, 0, "forces");
  ops.resize_sequence(bytes + forces.offset, forces, 2);
  const SchemaField& z = field(schema, forces.nested, "z");
  const double g = 9.81;
  std::memcpy(ops.sequence(bytes + forces.offset, forces).data + forces.element_size + z.offset, &g,
              sizeof(g));

  const SchemaField& labels = field(schema, 0, "labels");
  ops.resize_sequence(bytes + labels.offset, labels, 1);
  ops.assign_string(ops.sequence(bytes + labels.offset, labels).data,
                    "a label well beyond the small-string buffer");
  ops.resize_sequence(bytes + labels.offset, labels, 40);  // strings are copied, not moved bitwise

  EXPECT_EQ(std::string(wheel->header.frame_id.c_str()), "a frame id longer than sixteen bytes");
  EXPECT_EQ(std::string(wheel->name.c_str()), "fl");
  ASSERT_EQ(wheel->speeds.size(), 1000u);
  EXPECT_EQ(wheel->speeds[0], 1.5);
  EXPECT_EQ(wheel->speeds[2], 3.5);
  EXPECT_EQ(wheel->speeds[999], 0.0);
  ASSERT_EQ(wheel->forces.size(), 2u);
  EXPECT_EQ(wheel->forces[1].z, 9.81);
  ASSERT_EQ(wheel->labels.size(), 40u);
  EXPECT_EQ(std::string(wheel->labels[0].c_str()), "a label well beyond the small-string buffer");
  EXPECT_TRUE(wheel->labels[39].empty());

  // The C++ side keeps using it as its own: growth through std::vector works.
  wheel->labels.emplace_back("pushed by C++");
  EXPECT_EQ(ops.sequence(bytes + labels.offset, labels).count, 41u);
  wheel->~Wheel();
  detail::pool_deallocate(wheel);
}

TEST_F(ErasedMessageTest, BuiltByCppReadsAndCopiesThroughTheSchema) {
  const ErasedSchema schema = schema_for<sensor_msgs::msg::PointCloud2>();
  const ErasedOps ops(schema);
  auto* cloud = new (raw_message<sensor_msgs::msg::PointCloud2>()) sensor_msgs::msg::PointCloud2();
  cloud->header.frame_id = "lidar";
  cloud->width = 77;
  cloud->fields.resize(3);
  cloud->fields[2].name = "intensity, a name beyond the small-string buffer";
  cloud->fields[2].offset = 12;
  cloud->data.resize(4096);
  for (std::size_t i = 0; i < cloud->data.size(); ++i)
    cloud->data[i] = static_cast<std::uint8_t>(i);
  const auto* bytes = reinterpret_cast<const std::byte*>(cloud);

  const SchemaField& data = field(schema, 0, "data");
  const VectorSpan span = ops.sequence(bytes + data.offset, data);
  EXPECT_EQ(span.count, 4096u);
  EXPECT_EQ(static_cast<void*>(span.data), static_cast<void*>(cloud->data.data()));  // in place
  const SchemaField& fields = field(schema, 0, "fields");
  const SchemaField& name = field(schema, fields.nested, "name");
  EXPECT_EQ(ops.string_at(ops.sequence(bytes + fields.offset, fields).data +
                              2 * fields.element_size + name.offset,
                          name),
            "intensity, a name beyond the small-string buffer");

  auto* copy = raw_message<sensor_msgs::msg::PointCloud2>();
  ops.construct(copy, 0);
  ops.copy(copy, cloud, 0);
  EXPECT_EQ(std::string(copy->header.frame_id.c_str()), "lidar");
  EXPECT_EQ(copy->width, 77u);
  ASSERT_EQ(copy->fields.size(), 3u);
  EXPECT_EQ(std::string(copy->fields[2].name.c_str()),
            "intensity, a name beyond the small-string buffer");
  EXPECT_EQ(copy->fields[2].offset, 12u);
  ASSERT_EQ(copy->data.size(), 4096u);
  EXPECT_NE(copy->data.data(), cloud->data.data());
  EXPECT_EQ(std::memcmp(copy->data.data(), cloud->data.data(), 4096), 0);

  // Shrinking and destroying through the schema frees what C++ allocated.
  ops.resize_sequence(reinterpret_cast<std::byte*>(copy) + fields.offset, fields, 1);
  EXPECT_EQ(copy->fields.size(), 1u);
  ops.destroy(copy, 0);
  ops.destroy(cloud, 0);
  detail::pool_deallocate(copy);
  detail::pool_deallocate(cloud);
}

TEST_F(ErasedMessageTest, AReceivedMessagesContainersAreReadOnlyWithinItsMemory) {
  const ErasedSchema schema = schema_for<sensor_msgs::msg::PointCloud2>();
  const ErasedOps ops(schema);
  auto* cloud = new (raw_message<sensor_msgs::msg::PointCloud2>()) sensor_msgs::msg::PointCloud2();
  cloud->header.frame_id = "a frame name beyond the small-string buffer";
  cloud->data.resize(64);
  const auto* bytes = reinterpret_cast<const std::byte*>(cloud);
  // Memory that holds the message but not what its containers point to.
  const ForeignMemory only_the_message(std::span<const std::byte>(bytes, sizeof(*cloud)));
  const SchemaField& data = field(schema, 0, "data");
  EXPECT_EQ(ops.sequence(bytes + data.offset, data).count, 64u);  // trusted: read
  try {
    ops.sequence(bytes + data.offset, data, only_the_message);
    ADD_FAILURE() << "a sequence outside the memory was read";
  } catch (const InvalidMessage& error) {
    EXPECT_STREQ(error.what(),
                 "agnocast: field 'data' of a received message: sequence outside the "
                 "publisher's pool");
  }
  auto* copy = raw_message<sensor_msgs::msg::PointCloud2>();
  ops.construct(copy, 0);
  EXPECT_THROW(ops.copy(copy, cloud, 0, only_the_message), InvalidMessage);
  ops.destroy(copy, 0);
  detail::pool_deallocate(copy);
  cloud->~PointCloud2();
  detail::pool_deallocate(cloud);
}

TEST_F(ErasedMessageTest, RepeatedBuildAndDestroyLeavesThePoolAsItWas) {
  // Leaks would exhaust the 4 MiB test pool long before the last round.
  const ErasedSchema schema = schema_for<wheel_msgs::msg::Wheel>();
  const ErasedOps ops(schema);
  const SchemaField& labels = field(schema, 0, "labels");
  const SchemaField& speeds = field(schema, 0, "speeds");
  for (int round = 0; round < 2000; ++round) {
    auto* wheel = raw_message<wheel_msgs::msg::Wheel>();
    ops.construct(wheel, 0);
    auto* bytes = reinterpret_cast<std::byte*>(wheel);
    ops.resize_sequence(bytes + speeds.offset, speeds, 2000);
    ops.resize_sequence(bytes + labels.offset, labels, 8);
    for (std::size_t i = 0; i < 8; ++i) {
      ops.assign_string(ops.sequence(bytes + labels.offset, labels).data + i * labels.element_size,
                        std::string(100, 'x'));
    }
    ops.destroy(wheel, 0);
    detail::pool_deallocate(wheel);
  }
}

TEST_F(ErasedMessageTest, RefusesASchemaItCannotServe) {
  std::vector<std::uint8_t> blob(schema_of<std_msgs::msg::String>().begin(),
                                 schema_of<std_msgs::msg::String>().end());
  blob[16] ^= 0xFF;  // agnocast::string of another size than this library's
  EXPECT_THROW(ErasedSchema{blob}, SchemaError);
}

}  // namespace
}  // namespace agnocast::python
