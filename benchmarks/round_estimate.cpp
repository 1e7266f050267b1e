#include "round_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace agnocast::bench {

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const std::size_t middle = values.size() / 2;
  if (values.size() % 2 == 1) return values[middle];
  return (values[middle - 1] + values[middle]) / 2;
}

RoundEstimate estimate_over_rounds(const std::vector<double>& per_round) {
  std::vector<double> values;
  for (double value : per_round) {
    if (std::isfinite(value)) values.push_back(value);
  }
  RoundEstimate estimate;
  estimate.rounds = values.size();
  if (values.empty()) return estimate;
  estimate.value = median(values);
  // Percentile bootstrap; a fixed seed makes a report reproducible from its
  // per-round values.
  constexpr std::size_t resamples = 4000;
  std::mt19937_64 random(20261123);
  std::uniform_int_distribution<std::size_t> pick(0, values.size() - 1);
  std::vector<double> medians(resamples), resample(values.size());
  for (double& result : medians) {
    for (double& value : resample) value = values[pick(random)];
    result = median(resample);
  }
  std::sort(medians.begin(), medians.end());
  estimate.low = medians[static_cast<std::size_t>(0.025 * (resamples - 1))];
  estimate.high = medians[static_cast<std::size_t>(0.975 * (resamples - 1))];
  return estimate;
}

}  // namespace agnocast::bench
