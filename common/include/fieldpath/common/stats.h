#pragma once
/// Small statistics shared by the benchmarks and the study: timings are reported as medians of
/// repeated runs (the machine is shared, so the median resists stragglers better than the mean).
#include <algorithm>
#include <chrono>
#include <vector>

namespace fieldpath::common {

/// Median of `values` (mean of the middle two for an even count); 0 for an empty set.
inline double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Median wall time (s) of `run()` over `repeats` runs.
template <class Run>
double medianSeconds(int repeats, Run&& run) {
  std::vector<double> seconds;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    run();
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return median(std::move(seconds));
}

}  // namespace fieldpath::common
