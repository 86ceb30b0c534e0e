// Picking and closest points on the render surface, against the plate's known faces and brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Dense>

#include "cleave/surface/surface_bvh.hpp"
#include "surface_test_models.hpp"

namespace cleave {
namespace {

using test::builtin_model;

TEST(SurfaceBvh, RayAtThePlateCentreHitsTheTopFaceAtItsHeight) {
  const TissueModel model = builtin_model("plate");  // 100 x 100 x 10 mm, cells 2.5 mm
  const RenderSurface s = build_render_surface(model);
  const auto hit = pick_surface(s, s.reference_mm, Vec3(50.3, 49.1, 100.0), Vec3(0, 0, -2.0));
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point_mm.z(), 10.0, 1e-9);
  EXPECT_NEAR(hit->point_mm.x(), 50.3, 1e-9);
  EXPECT_NEAR(hit->point_mm.y(), 49.1, 1e-9);
  EXPECT_NEAR(hit->distance_mm, 90.0, 1e-9);
  EXPECT_NEAR(hit->normal.z(), 1.0, 1e-12);
  EXPECT_EQ(model.volume.cell_voxel(hit->cell), Vec3i(20, 19, 3));
  EXPECT_EQ(s.triangle_face(hit->triangle), 5);

  const auto below = pick_surface(s, s.reference_mm, Vec3(50.3, 49.1, -5.0), Vec3(0, 0, 1));
  ASSERT_TRUE(below.has_value());
  EXPECT_NEAR(below->point_mm.z(), 0.0, 1e-9);
  EXPECT_NEAR(below->normal.z(), -1.0, 1e-12);

  EXPECT_FALSE(pick_surface(s, s.reference_mm, Vec3(150, 50, 100), Vec3(0, 0, -1)).has_value());
  EXPECT_FALSE(pick_surface(s, s.reference_mm, Vec3(50, 50, 100), Vec3(0, 0, 1)).has_value());  // away from it
  EXPECT_FALSE(pick_surface(s, s.reference_mm, Vec3(50, 50, 100), Vec3::Zero()).has_value());
}

TEST(SurfaceBvh, PickingFollowsTheDeformedPositions) {
  const TissueModel model = builtin_model("plate");
  const RenderSurface s = build_render_surface(model);
  const std::vector<Vec3> lifted(static_cast<size_t>(model.volume.vertex_count()), Vec3(0, 0, 7.0));
  const auto hit = pick_surface(s, deformed_positions(s, model.volume, lifted), Vec3(50, 50, 100), Vec3(0, 0, -1));
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point_mm.z(), 17.0, 1e-9);
}

TEST(SurfaceBvh, ClosestPointSnapsToTheNearestFace) {
  const TissueModel model = builtin_model("plate");
  const RenderSurface s = build_render_surface(model);
  const SurfaceBvh bvh(s, s.reference_mm);
  const auto above = bvh.closest_point(Vec3(30, 60, 30));
  ASSERT_TRUE(above.has_value());
  EXPECT_NEAR((above->point_mm - Vec3(30, 60, 10)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(above->distance_mm, 20.0, 1e-9);
  const auto inside = bvh.closest_point(Vec3(30, 60, 1.5));
  ASSERT_TRUE(inside.has_value());
  EXPECT_NEAR(inside->point_mm.z(), 0.0, 1e-9);
  EXPECT_NEAR(inside->normal.z(), -1.0, 1e-12);
  const auto off_corner = bvh.closest_point(Vec3(-3, -4, 5));
  ASSERT_TRUE(off_corner.has_value());
  EXPECT_NEAR(off_corner->distance_mm, 5.0, 1e-9);  // to the edge x = y = 0
}

/// Point-triangle distance the plain way: inside the projection -> plane distance, else the
/// nearest of the three edges.
double brute_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  const Vec3 q = p - n.dot(p - a) * n;
  const bool inside = n.dot((b - a).cross(q - a)) >= 0 && n.dot((c - b).cross(q - b)) >= 0 &&
                      n.dot((a - c).cross(q - c)) >= 0;
  if (inside) return (p - q).norm();
  const auto segment = [&](const Vec3& u, const Vec3& v) {
    const double s = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    return (p - (u + s * (v - u))).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

/// First front-facing hit along the ray by solving o + t d = a + u (b - a) + v (c - a) per triangle.
double brute_ray(const Vec3& o, const Vec3& d, const RenderSurface& s) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : s.triangles) {
    const Vec3& a = s.reference_mm[static_cast<size_t>(t[0])];
    const Vec3& b = s.reference_mm[static_cast<size_t>(t[1])];
    const Vec3& c = s.reference_mm[static_cast<size_t>(t[2])];
    if ((b - a).cross(c - a).dot(d) >= 0) continue;
    Mat3 m;
    m << -d, b - a, c - a;
    const Vec3 x = m.colPivHouseholderQr().solve(o - a);
    if (x[0] >= 0 && x[1] >= 0 && x[2] >= 0 && x[1] + x[2] <= 1) best = std::min(best, x[0]);
  }
  return best;
}

TEST(SurfaceBvh, AgreesWithBruteForceOnTheTube) {
  const TissueModel model = builtin_model("cylinder");
  const RenderSurface s = build_render_surface(model);
  const SurfaceBvh bvh(s, s.reference_mm);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-20.0, 124.0);
  std::uniform_real_distribution<double> target(20.0, 64.0);
  for (int query = 0; query < 60; ++query) {
    const Vec3 p(coordinate(random), coordinate(random), coordinate(random));
    double brute = std::numeric_limits<double>::infinity();
    for (const auto& t : s.triangles)
      brute = std::min(brute, brute_distance(p, s.reference_mm[static_cast<size_t>(t[0])],
                                             s.reference_mm[static_cast<size_t>(t[1])],
                                             s.reference_mm[static_cast<size_t>(t[2])]));
    const auto hit = bvh.closest_point(p);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->distance_mm, brute, 1e-9);
    EXPECT_NEAR((hit->point_mm - p).norm(), hit->distance_mm, 1e-9);

    const Vec3 d = Vec3(target(random), target(random), target(random)) - p;
    const double expected_t = brute_ray(p, d.normalized(), s);
    const auto ray = bvh.pick(p, d);
    ASSERT_EQ(ray.has_value(), std::isfinite(expected_t));
    if (ray) {
      EXPECT_NEAR(ray->distance_mm, expected_t, 1e-7);
    }
  }
}

}  // namespace
}  // namespace cleave
