#include "cleave/cut/scalpel_links.hpp"

#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

constexpr double kSampleSpacingCells = 0.5;
constexpr double kAboveSkinCells = 1.0;

}  // namespace

SweptPath sweep_path(const BodySurface& surface, const std::vector<Vec3>& path_mm, double blade_angle_deg,
                     double tolerance_mm, bool closed) {
  const double h = surface.cell_size_mm();
  for (std::size_t i = 0; i < path_mm.size(); ++i)
    if (!surface.project(path_mm[i], tolerance_mm))
      throw InputError(fmt::format("path point {} ({:.3g}, {:.3g}, {:.3g}) mm is {:.3g} mm off the body's surface; "
                                   "expected a point within {:.3g} mm of it",
                                   i, path_mm[i].x(), path_mm[i].y(), path_mm[i].z(),
                                   surface.distance_mm(path_mm[i]), tolerance_mm));
  std::vector<Vec3> corners = path_mm;
  if (closed && !corners.empty()) corners.push_back(corners.front());
  SweptPath out;
  const auto add = [&](const Vec3& p) {
    const auto s = surface.project(p, tolerance_mm + h);
    const SurfacePoint sp = s ? *s : SurfacePoint{p, surface.normal_at(p)};
    if (!out.skin_mm.empty()) out.length_mm += (sp.position_mm - out.skin_mm.back()).norm();
    out.skin_mm.push_back(sp.position_mm);
    out.normal.push_back(sp.normal);
  };
  for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
    const Vec3 a = corners[i];
    const Vec3 b = corners[i + 1];
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / (kSampleSpacingCells * h))));
    for (int k = 0; k < steps; ++k) add(a + (b - a) * (static_cast<double>(k) / steps));
  }
  if (!corners.empty()) add(corners.back());
  const double angle = blade_angle_deg * std::numbers::pi / 180.0;
  const std::size_t n = out.skin_mm.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 ahead = out.skin_mm[std::min(i + 1, n - 1)] - out.skin_mm[i > 0 ? i - 1 : 0];
    if (!(ahead.norm() > 0)) {
      out.blade.push_back(-out.normal[i]);
      continue;
    }
    // The blade stands in the plane normal to the path: inward normal without its along-path part.
    const Vec3 tangent = ahead.normalized();
    Vec3 inward = -(out.normal[i] - out.normal[i].dot(tangent) * tangent);
    inward = inward.norm() > 0 ? inward.normalized() : Vec3(-out.normal[i]);
    const Vec3 side = tangent.cross(inward);
    out.blade.push_back((std::cos(angle) * inward + std::sin(angle) * side).normalized());
  }
  return out;
}

std::vector<Triangle> swept_triangles(const SweptPath& path, double depth_mm, double cell_size_mm) {
  const double above = kAboveSkinCells * cell_size_mm;
  std::vector<Triangle> out;
  for (std::size_t i = 0; i + 1 < path.skin_mm.size(); ++i) {
    const Vec3 top0 = path.skin_mm[i] - above * path.blade[i];
    const Vec3 top1 = path.skin_mm[i + 1] - above * path.blade[i + 1];
    const Vec3 bot0 = path.skin_mm[i] + depth_mm * path.blade[i];
    const Vec3 bot1 = path.skin_mm[i + 1] + depth_mm * path.blade[i + 1];
    out.push_back({top0, top1, bot1});
    out.push_back({top0, bot1, bot0});
  }
  return out;
}

std::vector<CellFace> scalpel_links(const LinkedVolume& volume, const SweptPath& path, double depth_mm) {
  const std::vector<Triangle> triangles = swept_triangles(path, depth_mm, volume.grid().cell_size_mm);
  return links_crossing_triangles(volume, triangles);
}

}  // namespace cleave
