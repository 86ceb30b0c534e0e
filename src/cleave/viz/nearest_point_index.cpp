#include "cleave/viz/nearest_point_index.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"

namespace cleave {

NearestPointIndex::NearestPointIndex(std::span<const Vec3> points_mm, double bucket_mm)
    : points_(points_mm.begin(), points_mm.end()), bucket_(bucket_mm) {
  if (!(bucket_mm > 0) || !std::isfinite(bucket_mm))
    throw InputError(fmt::format("nearest point index: bucket size {} mm; expected a positive finite size", bucket_mm));
  if (points_.size() >= std::numeric_limits<std::uint32_t>::max())
    throw InputError(fmt::format("nearest point index: {} points; expected fewer than 2^32", points_.size()));
  if (points_.empty()) return;
  Vec3 lo = points_.front(), hi = points_.front();
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!points_[i].allFinite()) throw InputError(fmt::format("nearest point index: point {} is not finite", i));
    lo = lo.cwiseMin(points_[i]);
    hi = hi.cwiseMax(points_[i]);
  }
  origin_ = lo;
  // At most about 2^24 buckets: a coarser bucket for a far-flung set.
  const Vec3 extent = hi - lo;
  while ((extent / bucket_).prod() > 16.0e6) bucket_ *= 2;
  for (int a = 0; a < 3; ++a) dims_[a] = static_cast<int>(std::floor(extent[a] / bucket_)) + 1;
  const auto buckets = static_cast<std::size_t>(dims_.x()) * static_cast<std::size_t>(dims_.y()) * static_cast<std::size_t>(dims_.z());
  const auto flat = [&](const Vec3i& b) {
    return (static_cast<std::size_t>(b.z()) * static_cast<std::size_t>(dims_.y()) + static_cast<std::size_t>(b.y())) *
               static_cast<std::size_t>(dims_.x()) +
           static_cast<std::size_t>(b.x());
  };
  bucket_start_.assign(buckets + 1, 0);
  for (const Vec3& p : points_) ++bucket_start_[flat(bucket_of(p)) + 1];
  for (std::size_t b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
  items_.resize(points_.size());
  std::vector<std::uint32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
  for (std::size_t i = 0; i < points_.size(); ++i) items_[fill[flat(bucket_of(points_[i]))]++] = static_cast<std::uint32_t>(i);
}

Vec3i NearestPointIndex::bucket_of(const Vec3& p) const {
  Vec3i b;
  for (int a = 0; a < 3; ++a) {
    const double t = std::floor((p[a] - origin_[a]) / bucket_);
    b[a] = static_cast<int>(std::clamp(t, 0.0, static_cast<double>(dims_[a] - 1)));
  }
  return b;
}

std::size_t NearestPointIndex::nearest(const Vec3& p_mm) const {
  if (points_.empty()) return npos;
  const Vec3i centre = bucket_of(p_mm);
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_index = npos;
  const int max_ring = dims_.maxCoeff();
  for (int ring = 0; ring <= max_ring; ++ring) {
    // Every point in a bucket of ring r + 1 or farther is at least r buckets away from p (p lies
    // in its bucket or beyond the grid on the side of it): stop once the best beats that.
    if (best_index != npos && ring >= 1) {
      const double bound = static_cast<double>(ring - 1) * bucket_;
      if (best < bound * bound) break;
    }
    const Vec3i lo = (centre - Vec3i::Constant(ring)).cwiseMax(Vec3i::Zero());
    const Vec3i hi = (centre + Vec3i::Constant(ring)).cwiseMin(dims_ - Vec3i::Ones());
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) {
          const bool on_ring = std::abs(x - centre.x()) == ring || std::abs(y - centre.y()) == ring || std::abs(z - centre.z()) == ring;
          if (!on_ring) continue;
          const std::size_t b = (static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_.y()) + static_cast<std::size_t>(y)) *
                                    static_cast<std::size_t>(dims_.x()) +
                                static_cast<std::size_t>(x);
          for (std::uint32_t k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
            const std::size_t i = items_[k];
            const double d = (points_[i] - p_mm).squaredNorm();
            if (d < best || (d == best && i < best_index)) best = d, best_index = i;
          }
        }
  }
  return best_index;
}

}  // namespace cleave
