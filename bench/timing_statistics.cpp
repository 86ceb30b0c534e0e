#include "timing_statistics.hpp"

#include <algorithm>
#include <vector>

namespace cleave::bench {

TimingStatistics summarize_timings(std::span<const double> samples_ms) {
  TimingStatistics t;
  if (samples_ms.empty()) return t;
  std::vector<double> sorted(samples_ms.begin(), samples_ms.end());
  std::sort(sorted.begin(), sorted.end());
  const std::size_t n = sorted.size();
  t.count = static_cast<int>(n);
  t.min_ms = sorted.front();
  t.max_ms = sorted.back();
  t.median_ms = n % 2 == 1 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  return t;
}

}  // namespace cleave::bench
