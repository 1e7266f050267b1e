#include "round_estimate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace agnocast::bench {
namespace {

TEST(RoundEstimate, MedianOfOddAndEvenCounts) {
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2);
  EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_DOUBLE_EQ(median({}), 0);
}

TEST(RoundEstimate, IntervalBracketsTheMedianAndStaysInsideTheRounds) {
  std::vector<double> rounds;
  for (int i = 0; i < 25; ++i) rounds.push_back(1.0 + 0.01 * ((i * 7) % 25));
  const RoundEstimate estimate = estimate_over_rounds(rounds);
  EXPECT_EQ(estimate.rounds, 25u);
  EXPECT_DOUBLE_EQ(estimate.value, median(rounds));
  EXPECT_LE(estimate.low, estimate.value);
  EXPECT_GE(estimate.high, estimate.value);
  EXPECT_GE(estimate.low, 1.0);
  EXPECT_LE(estimate.high, 1.24);
  // Far narrower than the spread of the rounds themselves.
  EXPECT_LT(estimate.high - estimate.low, 0.2);
}

TEST(RoundEstimate, OneOutlyingRoundMovesNeitherTheMedianNorTheInterval) {
  std::vector<double> rounds(21, 1.0);
  rounds[5] = 40.0;
  const RoundEstimate estimate = estimate_over_rounds(rounds);
  EXPECT_DOUBLE_EQ(estimate.value, 1.0);
  EXPECT_DOUBLE_EQ(estimate.high, 1.0);
}

TEST(RoundEstimate, RoundsWithoutAValueAreLeftOut) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const RoundEstimate estimate =
      estimate_over_rounds({2.0, nan, std::numeric_limits<double>::infinity(), 2.0});
  EXPECT_EQ(estimate.rounds, 2u);
  EXPECT_DOUBLE_EQ(estimate.value, 2.0);
  EXPECT_EQ(estimate_over_rounds({nan}).rounds, 0u);
}

}  // namespace
}  // namespace agnocast::bench
