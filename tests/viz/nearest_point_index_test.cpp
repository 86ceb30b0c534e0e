// NearestPointIndex picks exactly the point a scan in order picks (ties: the lowest index), for
// queries inside, on and far outside the points' box; the cut-face depth uses it.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "cleave/core/error.hpp"
#include "cleave/viz/nearest_point_index.hpp"

namespace cleave {
namespace {

std::size_t scan_nearest(const std::vector<Vec3>& points, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  std::size_t index = NearestPointIndex::npos;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i] - p).squaredNorm();
    if (d < best) best = d, index = i;
  }
  return index;
}

TEST(NearestPointIndex, AgreesWithAScanIncludingTiesAndFarQueries) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> in_box(-20.0, 20.0), far(-500.0, 500.0);
  std::uniform_int_distribution<int> lattice(-10, 10);
  std::vector<Vec3> points;
  for (int i = 0; i < 3000; ++i) points.emplace_back(in_box(random), 0.25 * in_box(random), in_box(random));
  // lattice points (many equal distances) and exact duplicates
  for (int i = 0; i < 500; ++i) points.emplace_back(2.0 * lattice(random), 2.0 * lattice(random), 2.0 * lattice(random));
  for (int i = 0; i < 50; ++i) points.push_back(points[static_cast<std::size_t>(i) * 7]);
  for (const double bucket_mm : {0.5, 2.0, 50.0}) {
    const NearestPointIndex index(points, bucket_mm);
    int checked = 0;
    for (int q = 0; q < 1000; ++q) {
      Vec3 p;
      if (q % 4 == 0) p = Vec3(far(random), far(random), far(random));
      else if (q % 4 == 1) p = Vec3(1.0 * lattice(random), 2.0 * lattice(random), 1.0 * lattice(random));  // between lattice points
      else p = Vec3(in_box(random), in_box(random), in_box(random));
      ASSERT_EQ(index.nearest(p), scan_nearest(points, p)) << "bucket " << bucket_mm << " query " << p.transpose();
      ++checked;
    }
    EXPECT_EQ(checked, 1000);
  }
}

TEST(NearestPointIndex, EmptySetAndBadBucketSize) {
  const NearestPointIndex empty(std::vector<Vec3>{}, 1.0);
  EXPECT_EQ(empty.nearest(Vec3::Zero()), NearestPointIndex::npos);
  const std::vector<Vec3> one = {Vec3(1, 2, 3)};
  EXPECT_EQ(NearestPointIndex(one, 1.0).nearest(Vec3(100, -100, 7)), 0u);
  try {
    (void)NearestPointIndex(one, 0.0);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "nearest point index: bucket size 0 mm; expected a positive finite size");
  }
  const std::vector<Vec3> bad = {Vec3(0, 0, 0), Vec3(std::nan(""), 0, 0)};
  EXPECT_THROW((void)NearestPointIndex(bad, 1.0), InputError);
}

}  // namespace
}  // namespace cleave
