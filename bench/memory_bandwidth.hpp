#pragma once
// This machine's sustainable memory bandwidth, measured like STREAM's triad a[i] = b[i] + s c[i]
// on arrays far larger than the caches, with all hardware threads (TBB) and, for comparison,
// with one. The triad moves 3 doubles per element (2 loads, 1 store; write-allocate traffic is
// not counted, as in STREAM), so bandwidth = 24 bytes x elements / time.
//
//   MemoryBandwidth bw = measure_memory_bandwidth({});
//   bw.all_threads_GB_per_s, bw.one_thread_GB_per_s    // GB = 1e9 bytes; best of the repetitions
//
// The benchmark compares each stage's bytes moved per second with this figure to say whether
// the stage is bandwidth bound.
#include <cstddef>

namespace cleave::bench {

struct BandwidthOptions {
  std::size_t elements_per_array = std::size_t{1} << 24;  ///< 16 Mi doubles = 128 MiB per array
  int repetitions = 8;                                     ///< the best repetition is reported
};

struct MemoryBandwidth {
  double all_threads_GB_per_s = 0;  ///< triad with every TBB worker
  double one_thread_GB_per_s = 0;   ///< triad on one thread
  int threads = 1;                  ///< TBB workers used for the first figure
  std::size_t bytes_per_array = 0;
};

MemoryBandwidth measure_memory_bandwidth(const BandwidthOptions& options);

}  // namespace cleave::bench
