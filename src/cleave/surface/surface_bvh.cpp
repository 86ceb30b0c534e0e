#include "cleave/surface/surface_bvh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

constexpr std::int32_t kLeafTriangles = 4;
/// Rays closer to parallel with a triangle than this (|det| relative to the edge lengths) miss it.
constexpr double kParallelTolerance = 1e-12;

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double box_distance_squared(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
}

/// Entry distance of the ray into the box, or +inf when it misses within [0, t_max].
double ray_box(const Vec3& o, const Vec3& inv_d, const Vec3& lo, const Vec3& hi, double t_max) {
  double t0 = 0, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    double near = (lo[a] - o[a]) * inv_d[a];
    double far = (hi[a] - o[a]) * inv_d[a];
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
    if (t0 > t1) return std::numeric_limits<double>::infinity();
  }
  return t0;
}

}  // namespace

SurfaceBvh::SurfaceBvh(const RenderSurface& surface, const std::vector<Vec3>& positions_mm) {
  if (positions_mm.size() != surface.reference_mm.size())
    throw InputError(fmt::format("surface picking: {} positions given for a surface of {} vertices",
                                 positions_mm.size(), surface.reference_mm.size()));
  const auto n = static_cast<size_t>(surface.triangle_count());
  corners_.resize(n);
  cell_.resize(n);
  order_.resize(n);
  for (size_t t = 0; t < n; ++t) {
    for (size_t i = 0; i < 3; ++i) corners_[t][i] = positions_mm[static_cast<size_t>(surface.triangles[t][i])];
    cell_[t] = surface.triangle_cell(static_cast<std::int32_t>(t));
    order_[t] = static_cast<std::int32_t>(t);
  }
  if (n > 0) {
    nodes_.reserve(4 * n / kLeafTriangles + 2);
    nodes_.resize(1);
    build(0, 0, static_cast<std::int32_t>(n));
  }
}

void SurfaceBvh::build(std::int32_t node, std::int32_t first, std::int32_t count) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  Vec3 centre_lo = lo, centre_hi = hi;
  for (std::int32_t i = first; i < first + count; ++i) {
    const auto& c = corners_[static_cast<size_t>(order_[static_cast<size_t>(i)])];
    for (const Vec3& p : c) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Vec3 centre = (c[0] + c[1] + c[2]) / 3.0;
    centre_lo = centre_lo.cwiseMin(centre);
    centre_hi = centre_hi.cwiseMax(centre);
  }
  Node& n = nodes_[static_cast<size_t>(node)];
  n.lo = lo;
  n.hi = hi;
  if (count <= kLeafTriangles) {
    n.first = first;
    n.count = count;
    return;
  }
  int axis = 0;
  (centre_hi - centre_lo).maxCoeff(&axis);
  const std::int32_t half = count / 2;
  const auto begin = order_.begin() + first;
  std::nth_element(begin, begin + half, begin + count, [&](std::int32_t a, std::int32_t b) {
    const auto& ca = corners_[static_cast<size_t>(a)];
    const auto& cb = corners_[static_cast<size_t>(b)];
    return ca[0][axis] + ca[1][axis] + ca[2][axis] < cb[0][axis] + cb[1][axis] + cb[2][axis];
  });
  // Children lie next to each other: left at `left`, right at `left + 1`.
  const auto left = static_cast<std::int32_t>(nodes_.size());
  n.first = left;
  n.count = 0;
  nodes_.resize(nodes_.size() + 2);  // invalidates `n`
  build(left, first, half);
  build(left + 1, first + half, count - half);
}

SurfaceHit SurfaceBvh::hit_of(std::int32_t t, const Vec3& point_mm, double distance_mm) const {
  const auto& c = corners_[static_cast<size_t>(t)];
  SurfaceHit hit;
  hit.point_mm = point_mm;
  hit.triangle = t;
  hit.cell = cell_[static_cast<size_t>(t)];
  const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);
  hit.normal = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitZ();
  hit.distance_mm = distance_mm;
  return hit;
}

std::optional<SurfaceHit> SurfaceBvh::pick(const Vec3& origin_mm, const Vec3& direction) const {
  const double length = direction.norm();
  if (nodes_.empty() || !(length > 0) || !origin_mm.allFinite() || !direction.allFinite()) return std::nullopt;
  const Vec3 d = direction / length;
  const Vec3 inv_d = d.cwiseInverse();
  double best_t = std::numeric_limits<double>::infinity();
  std::int32_t best = kNone;
  std::vector<std::int32_t> stack{0};
  while (!stack.empty()) {
    const Node& node = nodes_[static_cast<size_t>(stack.back())];
    stack.pop_back();
    if (ray_box(origin_mm, inv_d, node.lo, node.hi, best_t) == std::numeric_limits<double>::infinity()) continue;
    if (node.count == 0) {
      stack.push_back(node.first);
      stack.push_back(node.first + 1);
      continue;
    }
    for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
      const std::int32_t t = order_[static_cast<size_t>(i)];
      const auto& c = corners_[static_cast<size_t>(t)];
      // Moller-Trumbore, front faces only (det = -d . (e1 x e2) > 0 for a counter-clockwise triangle facing the ray).
      const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
      const Vec3 p = d.cross(e2);
      const double det = e1.dot(p);
      if (!(det > kParallelTolerance * e1.squaredNorm())) continue;
      const Vec3 s = origin_mm - c[0];
      const double u = s.dot(p) / det;
      if (u < 0 || u > 1) continue;
      const Vec3 q = s.cross(e1);
      const double v = d.dot(q) / det;
      if (v < 0 || u + v > 1) continue;
      const double tt = e2.dot(q) / det;
      if (tt >= 0 && tt < best_t) {
        best_t = tt;
        best = t;
      }
    }
  }
  if (best == kNone) return std::nullopt;
  return hit_of(best, origin_mm + best_t * d, best_t);
}

std::optional<SurfaceHit> SurfaceBvh::closest_point(const Vec3& point_mm) const {
  if (nodes_.empty() || !point_mm.allFinite()) return std::nullopt;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::int32_t best = kNone;
  Vec3 best_point = Vec3::Zero();
  std::vector<std::int32_t> stack{0};
  while (!stack.empty()) {
    const Node& node = nodes_[static_cast<size_t>(stack.back())];
    stack.pop_back();
    if (box_distance_squared(point_mm, node.lo, node.hi) >= best_d2) continue;
    if (node.count == 0) {
      // Visit the nearer child first (pushed last).
      const Node& a = nodes_[static_cast<size_t>(node.first)];
      const Node& b = nodes_[static_cast<size_t>(node.first + 1)];
      const bool a_nearer = box_distance_squared(point_mm, a.lo, a.hi) < box_distance_squared(point_mm, b.lo, b.hi);
      stack.push_back(a_nearer ? node.first + 1 : node.first);
      stack.push_back(a_nearer ? node.first : node.first + 1);
      continue;
    }
    for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
      const std::int32_t t = order_[static_cast<size_t>(i)];
      const auto& c = corners_[static_cast<size_t>(t)];
      const Vec3 q = closest_on_triangle(point_mm, c[0], c[1], c[2]);
      const double d2 = (q - point_mm).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = t;
        best_point = q;
      }
    }
  }
  if (best == kNone) return std::nullopt;
  return hit_of(best, best_point, std::sqrt(best_d2));
}

std::optional<SurfaceHit> pick_surface(const RenderSurface& surface, const std::vector<Vec3>& positions_mm,
                                       const Vec3& ray_origin_mm, const Vec3& ray_direction) {
  return SurfaceBvh(surface, positions_mm).pick(ray_origin_mm, ray_direction);
}

std::optional<SurfaceHit> closest_surface_point(const RenderSurface& surface, const std::vector<Vec3>& positions_mm,
                                                const Vec3& point_mm) {
  return SurfaceBvh(surface, positions_mm).closest_point(point_mm);
}

}  // namespace cleave
