// The generated golden headers compiled: names, defaults, constants, traits, hash.
#include <gtest/gtest.h>

#include <fstream>
#include <golden_msgs/msg/empty.hpp>
#include <golden_msgs/msg/wheel.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <sstream>
#include <type_traits>

#include "kernel/runtime.hpp"

namespace same {
// golden_msgs/Tire written by hand with the same layout...
struct Tire {
  std::uint16_t pressure_kpa;
  agnocast::string brand;
};
}  // namespace same
AGNOCAST_MESSAGE(same::Tire, "golden_msgs/msg/Tire", pressure_kpa, brand);

namespace changed {
// ...and with one field's type changed.
struct Tire {
  std::uint32_t pressure_kpa;
  agnocast::string brand;
};
}  // namespace changed
AGNOCAST_MESSAGE(changed::Tire, "golden_msgs/msg/Tire", pressure_kpa, brand);

namespace {

using agnocast::message_traits;
using golden_msgs::msg::Wheel;

TEST(GeneratedMessage, NamesFollowRos2) {
  EXPECT_EQ(message_traits<Wheel>::type_name, "golden_msgs/msg/Wheel");
  EXPECT_EQ(message_traits<sensor_msgs::msg::PointCloud2>::type_name,
            "sensor_msgs/msg/PointCloud2");
  static_assert(agnocast::Publishable<Wheel>);
  static_assert(agnocast::DeclaredMessage<golden_msgs::msg::Empty>);
}

TEST(GeneratedMessage, ConstantsAndDefaults) {
  static_assert(Wheel::MODE_DRIVE == 1);
  static_assert(Wheel::LABEL == "front # left");
  static_assert(Wheel::MIN_TICKS == INT64_MIN);
  static_assert(std::is_same_v<decltype(Wheel::tags), agnocast::vector<agnocast::string>>);
  static_assert(std::is_same_v<decltype(Wheel::ticks), std::array<std::int32_t, 3>>);
  static constexpr std::size_t pool_size = 1 << 20;
  auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
  agnocast::detail::Runtime::install_for_testing(region, pool_size);
  const Wheel wheel;
  EXPECT_EQ(wheel.name, "wheel");
  EXPECT_EQ(wheel.radius, 0.3);
  EXPECT_EQ(wheel.ticks, (std::array<std::int32_t, 3>{1, -2, 3}));
  EXPECT_EQ(wheel.tags.size(), 2u);
  EXPECT_EQ(wheel.tags[1], "b,c");
  EXPECT_TRUE(wheel.enabled);
  EXPECT_EQ(wheel.tire.pressure_kpa, 220);
  EXPECT_EQ(wheel.odometer, UINT64_MAX);
  EXPECT_EQ(wheel.status, 0);
}

// The .msg file travels with the type, byte for byte, for bags and tools.
TEST(GeneratedMessage, DefinitionIsTheMsgFileAsItIs) {
  std::ifstream file(std::string(GOLDEN_MSGS_DIR) + "/Wheel.msg", std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  ASSERT_FALSE(text.str().empty());
  EXPECT_EQ(agnocast::message_traits<golden_msgs::msg::Wheel>::definition, text.str());
  EXPECT_EQ(agnocast::message_traits<golden_msgs::msg::Wheel>::descriptor.definition, text.str());
}

TEST(GeneratedMessage, DescriptorMatchesTheStruct) {
  const auto& fields = message_traits<Wheel>::fields;
  ASSERT_EQ(fields.size(), 14u);
  EXPECT_EQ(fields[6].name, "tags");
  EXPECT_EQ(fields[6].kind, agnocast::FieldKind::String);
  EXPECT_EQ(fields[6].shape, agnocast::FieldShape::Sequence);
  EXPECT_EQ(fields[6].sequence_bound, 4u);
  EXPECT_EQ(fields[6].string_bound, 8u);
  EXPECT_EQ(fields[6].offset, offsetof(Wheel, tags));
  EXPECT_EQ(fields[9].shape, agnocast::FieldShape::Array);
  EXPECT_EQ(fields[9].array_length, 2u);
  EXPECT_EQ(fields[9].nested, &message_traits<golden_msgs::msg::Tire>::descriptor);
  EXPECT_EQ(message_traits<Wheel>::descriptor.size, sizeof(Wheel));
}

TEST(GeneratedMessage, HashTellsDefinitionsApart) {
  // The same name and layout match, whoever wrote the struct.
  EXPECT_EQ(message_traits<same::Tire>::type_hash,
            message_traits<golden_msgs::msg::Tire>::type_hash);
  EXPECT_NE(message_traits<changed::Tire>::type_hash,
            message_traits<golden_msgs::msg::Tire>::type_hash);
  EXPECT_NE(message_traits<Wheel>::type_hash, message_traits<golden_msgs::msg::Tire>::type_hash);
  // A nested type's change reaches the outer hash: Wheel's differs from one computed
  // with a different Tire hash.
  std::array<agnocast::FieldDescriptor, 14> fields = message_traits<Wheel>::fields;
  fields[1].nested = &message_traits<changed::Tire>::descriptor;
  EXPECT_NE(agnocast::detail::declared_type_hash("golden_msgs/msg/Wheel", sizeof(Wheel),
                                                 alignof(Wheel), fields),
            message_traits<Wheel>::type_hash);
  EXPECT_EQ(message_traits<int>::type_name, "raw:4:4");
  EXPECT_EQ(message_traits<int>::type_hash, message_traits<float>::type_hash);
}

TEST(GeneratedMessage, HashIsStable) {
  // Programs built by different agnocast releases meet on one topic: the hash of
  // a layout must not drift. Change these only together with the recipe's tag
  // ("agnocast-type-v1"/"agnocast-raw-v1" in message_traits.hpp).
  EXPECT_EQ(message_traits<std::uint32_t>::type_hash, 0xc1f6888313b183edULL);
#if defined(__x86_64__) && defined(__GLIBCXX__) && _GLIBCXX_USE_CXX11_ABI
  EXPECT_EQ(message_traits<golden_msgs::msg::Tire>::type_hash, 0x932c77e9b3d56ddaULL);
  EXPECT_EQ(message_traits<Wheel>::type_hash, 0xedea4a7db3387b16ULL);
#endif
}

}  // namespace
