// How a ratio measured once per round becomes one number and its 95 %
// interval: the median over rounds, bootstrapped over rounds.
#pragma once

#include <cstddef>
#include <vector>

namespace agnocast::bench {

struct RoundEstimate {
  double value = 0;  // median of the per-round values
  double low = 0;    // 95 % bootstrap interval of that median
  double high = 0;
  std::size_t rounds = 0;
};

double median(std::vector<double> values);

// Rounds whose value is not finite (a zero denominator) are left out.
RoundEstimate estimate_over_rounds(const std::vector<double>& per_round);

}  // namespace agnocast::bench
