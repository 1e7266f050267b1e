// Heap messages (AGNOCAST_HEAP_MESSAGE) in a process without the allocation hook.
#include <gtest/gtest.h>

#include <string>

#include "agnocast/errors.hpp"
#include "agnocast/heap_scope.hpp"
#include "agnocast/node.hpp"
#include "kernel/fake_runtime.hpp"
#include "seed_message_agnocast.hpp"

// seed::Msg written with agnocast containers: the same bytes in the pool.
namespace twin {
struct Tag {
  agnocast::string key;
  agnocast::vector<std::int32_t> values;
};
struct Msg {
  std::uint64_t seq = 0;
  agnocast::vector<std::uint8_t> payload;
  agnocast::string frame_id;
  agnocast::vector<seed::Point> points;
  agnocast::vector<Tag> tags;
};
}  // namespace twin
AGNOCAST_MESSAGE(twin::Tag, "seed/msg/Tag", key, values);
AGNOCAST_MESSAGE(twin::Msg, "seed/msg/Msg", seq, payload, frame_id, points, tags);

namespace agnocast::detail {
namespace {

static_assert(HeapMessage<seed::Msg> && HeapMessage<seed::Tag>);
static_assert(!HeapMessage<twin::Msg> && !HeapMessage<Counted>);
static_assert(Publishable<seed::Msg>);

TEST(HeapMessage, IsDescribedAndHashedAsItsTwinWithAgnocastContainers) {
  EXPECT_EQ(message_traits<seed::Msg>::type_hash, message_traits<twin::Msg>::type_hash);
  const auto& fields = message_traits<seed::Msg>::fields;
  ASSERT_EQ(fields.size(), 5U);
  EXPECT_EQ(fields[1].shape, FieldShape::Sequence);
  EXPECT_EQ(fields[1].kind, FieldKind::UInt8);
  EXPECT_EQ(fields[2].kind, FieldKind::String);
  EXPECT_EQ(fields[4].kind, FieldKind::Message);
  EXPECT_EQ(fields[4].nested, &message_traits<seed::Tag>::descriptor);
}

using HeapMessageTest = FakeRuntimeTest;

TEST_F(HeapMessageTest, APublisherNeedsTheHookAndSaysHowToEnableIt) {
  ASSERT_FALSE(heap_scope::hook_active());
  Node node{"no_hook"};
  try {
    node.create_publisher<seed::Msg>(topic("heap"), QoS{1});
    FAIL() << "created a publisher of a heap message without the hook";
  } catch (const Error& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("seed/msg/Msg"), std::string::npos) << what;
    EXPECT_NE(what.find("LD_PRELOAD=libagnocast_heaphook.so"), std::string::npos) << what;
    EXPECT_NE(what.find("agnocast::heaphook"), std::string::npos) << what;
  }
}

TEST_F(HeapMessageTest, ASubscriberOnlyReadsAndNeedsNoHook) {
  Node node{"no_hook"};
  EXPECT_NO_THROW(node.create_polling_subscriber<seed::Msg>(topic("heap"), QoS{1}));
}

TEST_F(HeapMessageTest, AScopeWithoutTheHookChangesNothing) {
  heap_scope scope;
  auto block = std::make_unique<int>(1);
  EXPECT_FALSE(runtime().owns(block.get()));
}

}  // namespace
}  // namespace agnocast::detail
