#pragma once
// Entry-wise vector work on all cores, in fixed ranges of 16k entries: the CG's and the dynamic
// step's passes over 150k-dof vectors (each about 0.1 ms serial), and the CG's double vectors
// copied to and from the V-cycle's and the operator's float ones.
//
//   for_each_range(n, [&](Eigen::Index begin, Eigen::Index end) { ... });
//   cast_in_parallel(r, r_single);   // r_single = r.cast<float>(), resized
#include <Eigen/Core>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace cleave {

inline constexpr Eigen::Index kEntriesPerRange = Eigen::Index{1} << 14;

/// each(begin, end) over [0, n) in parallel ranges of kEntriesPerRange entries.
template <typename Each>
void for_each_range(Eigen::Index n, Each&& each) {
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, kEntriesPerRange),
                    [&](const tbb::blocked_range<Eigen::Index>& r) { each(r.begin(), r.end()); });
}

template <typename From, typename To>
void cast_in_parallel(const From& from, To& to) {
  using Scalar = typename To::Scalar;
  to.resize(from.size());
  for_each_range(from.size(), [&](Eigen::Index begin, Eigen::Index end) {
    to.segment(begin, end - begin) = from.segment(begin, end - begin).template cast<Scalar>();
  });
}

}  // namespace cleave
