#include "bag/qos_profiles.hpp"

#include <gtest/gtest.h>

namespace agnocast::cli {
namespace {

TEST(QosProfiles, RecordWritesRmwsNumbersPerPublisher) {
  const std::string qos = offered_qos_profiles({{10, false}, {1, true}});
  EXPECT_EQ(qos.find("- history: 1\n  depth: 10\n  reliability: 1\n  durability: 2\n"), 0u);
  EXPECT_NE(qos.find("- history: 1\n  depth: 1\n  reliability: 1\n  durability: 1\n"),
            std::string::npos);
}

TEST(QosProfiles, PlayOffersWhatTheRecordedPublishersOffered) {
  const QoS volatile_ten = played_qos(offered_qos_profiles({{10, false}}), 10);
  EXPECT_EQ(volatile_ten.depth(), 10u);
  EXPECT_FALSE(volatile_ten.is_transient_local());
  // Any transient-local publisher makes the player one, at the deepest depth.
  const QoS mixed = played_qos(offered_qos_profiles({{10, false}, {100, true}, {5, true}}), 10);
  EXPECT_EQ(mixed.depth(), 100u);
  EXPECT_TRUE(mixed.is_transient_local());
}

TEST(QosProfiles, PlayReadsRosbag2sWordsToo) {
  const QoS words = played_qos(
      "- history: keep_last\n"
      "  depth: 25\n"
      "  reliability: reliable\n"
      "  durability: transient_local\n"
      "  deadline:\n"
      "    sec: 9223372036\n"
      "    nsec: 854775807\n",
      10);
  EXPECT_EQ(words.depth(), 25u);
  EXPECT_TRUE(words.is_transient_local());
  EXPECT_FALSE(played_qos("- history: keep_last\n  depth: 3\n  durability: volatile\n", 10)
                   .is_transient_local());
}

TEST(QosProfiles, PlayFallsBackToItsDefaultAndTheKernelsBounds) {
  const QoS none = played_qos("", 10);
  EXPECT_EQ(none.depth(), 10u);
  EXPECT_FALSE(none.is_transient_local());
  EXPECT_EQ(played_qos("- history: keep_all\n  depth: 0\n  durability: 1\n", 10).depth(), 10u);
  EXPECT_EQ(played_qos("- depth: 100000\n", 10).depth(), 1024u);
  EXPECT_EQ(played_qos("- depth: -3\n- depth: 12x\n- depth:\nnot yaml at all: [\n", 10).depth(),
            10u);
  EXPECT_EQ(played_qos("- depth: 99999999999999999999999999\n", 10).depth(), 10u);
}

}  // namespace
}  // namespace agnocast::cli
