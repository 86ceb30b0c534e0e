#include "cleave/cut/flap_links.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/cut/links_crossing_surface.hpp"
#include "cleave/cut/round_incision_links.hpp"

namespace cleave {
namespace {

constexpr double kDepthStepCells = 0.25;

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Proper or touching intersection of segments [p0, p1] and [q0, q1].
bool segments_intersect(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1) {
  const double d1 = cross2(q1 - q0, p0 - q0);
  const double d2 = cross2(q1 - q0, p1 - q0);
  const double d3 = cross2(p1 - p0, q0 - p0);
  const double d4 = cross2(p1 - p0, q1 - p0);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  const auto on = [](const Vec2& a, const Vec2& b, const Vec2& p, double d) {
    return d == 0 && p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) &&
           p.y() >= std::min(a.y(), b.y()) && p.y() <= std::max(a.y(), b.y());
  };
  return on(q0, q1, p0, d1) || on(q0, q1, p1, d2) || on(p0, p1, q0, d3) || on(p0, p1, q1, d4);
}

double polygon_area(const std::vector<Vec2>& poly) {
  double a = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) a += cross2(poly[i], poly[(i + 1) % poly.size()]);
  return 0.5 * std::abs(a);
}

/// Distance from p along `up` to where the body ends (marching in quarter cells).
double depth_below_skin(const BodySurface& surface, const Vec3& p, const Vec3& up) {
  const double step = kDepthStepCells * surface.cell_size_mm();
  double s = 0;
  while (surface.inside(p + s * up) && s <= surface.model().size_mm()) s += step;
  return std::max(0.0, s - 0.5 * step);
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> polygon_self_intersections(const std::vector<Vec2>& poly) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segments_intersect(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n])) out.emplace_back(i, j);
    }
  return out;
}

bool polygon_contains(const std::vector<Vec2>& poly, const Vec2& p) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

FlapRegion flap_region(const BodySurface& surface, const Flap& flap, double tolerance_mm) {
  const double h = surface.cell_size_mm();
  FlapRegion r;
  r.shape = flap.shape;
  r.depth_mm = flap.depth_mm;
  std::vector<SurfacePoint> snapped;
  for (std::size_t i = 0; i < flap.path_mm.size(); ++i) {
    const auto s = surface.project(flap.path_mm[i], tolerance_mm);
    if (!s)
      throw InputError(fmt::format("flap path point {} ({:.3g}, {:.3g}, {:.3g}) mm is {:.3g} mm off the body's "
                                   "surface; expected a point within {:.3g} mm of it",
                                   i, flap.path_mm[i].x(), flap.path_mm[i].y(), flap.path_mm[i].z(),
                                   surface.distance_mm(flap.path_mm[i]), tolerance_mm));
    if (!snapped.empty() && (s->position_mm - snapped.back().position_mm).norm() < 1e-9 * h) continue;
    snapped.push_back(*s);
  }
  if (snapped.size() >= 2 && (snapped.front().position_mm - snapped.back().position_mm).norm() < 1e-9 * h)
    snapped.pop_back();
  if (snapped.size() < 3)
    throw InputError(fmt::format("flap path has {} distinct points; expected at least 3", snapped.size()));
  Vec3 normal_sum = Vec3::Zero();
  for (const SurfacePoint& s : snapped) {
    r.origin_mm += s.position_mm / static_cast<double>(snapped.size());
    normal_sum += s.normal;
  }
  r.normal = normal_sum.normalized();
  std::tie(r.tangent_u, r.tangent_v) = tangent_frame(r.normal);
  for (const SurfacePoint& s : snapped) r.polygon.push_back(r.to_plane(s.position_mm));
  const auto crossings = polygon_self_intersections(r.polygon);
  if (!crossings.empty())
    throw InputError(fmt::format("flap path intersects itself (segment {} crosses segment {}{}); expected a simple "
                                 "closed or U-shaped path",
                                 crossings.front().first, crossings.front().second,
                                 flap.shape == FlapShape::u_shaped && crossings.front().second == r.polygon.size() - 1
                                     ? ", the hinge between its ends"
                                     : ""));
  const double area = polygon_area(r.polygon);
  if (area < h * h)
    throw InputError(fmt::format("flap path encloses {:.3g} mm^2; expected at least one cell face ({:.3g} mm^2)",
                                 area, h * h));
  // Cells belong to the flap only within a slab under the path (not the far side of a shell).
  double sag_mm = 0;
  for (const SurfacePoint& s : snapped) sag_mm = std::max(sag_mm, std::abs((s.position_mm - r.origin_mm).dot(r.normal)));
  const double slab_top_mm = sag_mm + h;
  const double slab_bottom_mm = -(flap.depth_mm + sag_mm + h);
  const LinkedVolume& volume = surface.model().volume;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Vec3 p = volume.cell_center_mm(c);
    const double height = (p - r.origin_mm).dot(r.normal);
    if (height > slab_top_mm || height < slab_bottom_mm) continue;
    if (!polygon_contains(r.polygon, r.to_plane(p))) continue;
    if (depth_below_skin(surface, p, r.normal) < flap.depth_mm) r.cells.push_back(c);
  }
  return r;
}

std::vector<CellFace> flap_links(const LinkedVolume& volume, const FlapRegion& region) {
  std::vector<std::uint8_t> in_flap(static_cast<std::size_t>(volume.cell_count()), 0);
  for (const CellId c : region.cells) in_flap[static_cast<std::size_t>(c)] = 1;
  const auto in_a = [&](CellId c) { return in_flap[static_cast<std::size_t>(c)] != 0; };
  const std::size_t n = region.polygon.size();
  const auto keep = [&](CellId c, CellId nb) {
    if (region.shape == FlapShape::closed) return true;
    const Vec2 a = region.to_plane(volume.cell_center_mm(c));
    const Vec2 b = region.to_plane(volume.cell_center_mm(nb));
    if (polygon_contains(region.polygon, b)) return true;  // undercut
    return !segments_intersect(a, b, region.polygon[n - 1], region.polygon[0]);  // the hinge stays attached
  };
  return links_leaving(volume, region.cells, in_a, keep);
}

}  // namespace cleave
