#pragma once
// A vector copied into another precision on all cores (the CG's double vectors to and from the
// V-cycle's and the operator's float ones: a serial cast cost about 0.1 ms at 150k dofs, several
// per iteration).
//
//   cast_in_parallel(r, r_single);   // r_single = r.cast<float>(), resized
#include <Eigen/Core>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace cleave {

template <typename From, typename To>
void cast_in_parallel(const From& from, To& to) {
  using Scalar = typename To::Scalar;
  constexpr Eigen::Index kEntriesPerRange = Eigen::Index{1} << 14;
  to.resize(from.size());
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, from.size(), kEntriesPerRange), [&](const tbb::blocked_range<Eigen::Index>& r) {
    to.segment(r.begin(), r.end() - r.begin()) = from.segment(r.begin(), r.end() - r.begin()).template cast<Scalar>();
  });
}

}  // namespace cleave
