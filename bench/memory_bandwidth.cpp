#include "memory_bandwidth.hpp"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "timing_statistics.hpp"

namespace cleave::bench {
namespace {

constexpr double kTriadBytesPerElement = 3.0 * sizeof(double);  // read b, read c, write a
constexpr double kTriadScale = 3.0;
constexpr std::size_t kChunkElements = std::size_t{1} << 16;  // one TBB task: 64 Ki doubles

/// Best triad bandwidth (GB/s) over `repetitions` passes with the current TBB parallelism.
double best_triad_GB_per_s(std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c,
                           int repetitions) {
  const std::size_t n = a.size();
  double best_ms = 0;
  for (int r = 0; r < repetitions; ++r) {
    const double ms = wall_time_ms([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kChunkElements),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i < range.end(); ++i) a[i] = b[i] + kTriadScale * c[i];
                        },
                        tbb::static_partitioner{});
    });
    if (r == 0 || ms < best_ms) best_ms = ms;
  }
  return best_ms > 0 ? kTriadBytesPerElement * static_cast<double>(n) / (best_ms * 1e6) : 0;
}

}  // namespace

MemoryBandwidth measure_memory_bandwidth(const BandwidthOptions& options) {
  const std::size_t n = std::max<std::size_t>(options.elements_per_array, kChunkElements);
  const int repetitions = std::max(options.repetitions, 1);
  std::vector<double> a(n), b(n), c(n);
  // First touch in parallel so pages are spread like the triad will read them.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kChunkElements),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        a[i] = 0.0;
                        b[i] = 1.0;
                        c[i] = 2.0;
                      }
                    },
                    tbb::static_partitioner{});
  MemoryBandwidth result;
  result.bytes_per_array = n * sizeof(double);
  result.threads = tbb::info::default_concurrency();
  result.all_threads_GB_per_s = best_triad_GB_per_s(a, b, c, repetitions);
  {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    result.one_thread_GB_per_s = best_triad_GB_per_s(a, b, c, repetitions);
  }
  return result;
}

}  // namespace cleave::bench
