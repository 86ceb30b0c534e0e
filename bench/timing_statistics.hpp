#pragma once
// Repeated wall-clock measurements reduced to what the benchmark reports: median, min and max.
//
//   std::vector<double> samples_ms;
//   for (int i = 0; i < repeat; ++i) samples_ms.push_back(wall_time_ms([&] { work(); }));
//   TimingStatistics t = summarize_timings(samples_ms);   // t.median_ms, t.min_ms, t.max_ms
//
// Edge cases: no samples gives all zeros and count 0 (a stage that was not run); an even count
// takes the mean of the two middle samples as the median.
#include <chrono>
#include <span>

namespace cleave::bench {

struct TimingStatistics {
  double median_ms = 0;
  double min_ms = 0;
  double max_ms = 0;
  int count = 0;  ///< number of samples; 0 = not measured
};

TimingStatistics summarize_timings(std::span<const double> samples_ms);

/// Wall-clock time (ms, steady clock) of one call of `work`.
template <class Work>
double wall_time_ms(Work&& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::milli>(stop - start).count();
}

}  // namespace cleave::bench
