#include "cleave/cut/place_incisions.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <random>

#include "cleave/core/error.hpp"
#include "cleave/cut/round_incision_links.hpp"

namespace cleave {
namespace {

constexpr int kRimChecks = 12;
constexpr double kRimToleranceCells = 0.75;  ///< rim points may lie this far off the surface
constexpr double kDepthSlackCells = 0.5;

bool rim_fits(const BodySurface& surface, const SurfacePoint& s, double radius_mm) {
  const auto [u, v] = tangent_frame(s.normal);
  const double tol = kRimToleranceCells * surface.cell_size_mm() + radius_mm * (1 - std::cos(std::numbers::pi / 6));
  for (int k = 0; k < kRimChecks; ++k) {
    const double t = 2 * std::numbers::pi * k / kRimChecks;
    const Vec3 p = s.position_mm + radius_mm * (std::cos(t) * u + std::sin(t) * v);
    const auto q = surface.project(p, tol);
    if (!q || q->normal.dot(s.normal) < 0.5) return false;
  }
  return true;
}

}  // namespace

bool IncisionRegion::contains(const Vec3& p_mm) const {
  switch (kind) {
    case Kind::whole_surface: return true;
    case Kind::box: return (p_mm.array() >= lo_mm.array()).all() && (p_mm.array() <= hi_mm.array()).all();
    case Kind::sphere: return (p_mm - centre_mm).norm() <= radius_mm;
  }
  return false;
}

std::vector<RoundIncision> place_incisions(const BodySurface& surface, const IncisionPattern& pattern) {
  const double h = surface.cell_size_mm();
  if (!(pattern.radius_mm >= h) || !std::isfinite(pattern.radius_mm))
    throw InputError(fmt::format("incision radius {} mm; expected at least one cell ({:.3g} mm)", pattern.radius_mm, h));
  if (!(pattern.depth_mm > 0) || !std::isfinite(pattern.depth_mm))
    throw InputError(fmt::format("incision depth {} mm; expected a positive depth in mm", pattern.depth_mm));
  const double least_spacing = 2 * pattern.radius_mm + h;
  if (!(pattern.spacing_mm >= least_spacing) || !std::isfinite(pattern.spacing_mm))
    throw InputError(fmt::format("incision spacing {} mm; expected at least the diameter plus one cell ({:.3g} mm) "
                                 "so that incisions stay apart",
                                 pattern.spacing_mm, least_spacing));
  if (pattern.count && *pattern.count < 1)
    throw InputError(fmt::format("incision count {}; expected at least 1", *pattern.count));

  std::vector<SurfacePoint> candidates;
  for (const SurfacePoint& s : surface.samples(pattern.side))
    if (pattern.region.contains(s.position_mm)) candidates.push_back(s);
  std::mt19937 rng(pattern.seed);
  for (std::size_t i = candidates.size(); i > 1; --i) {  // Fisher-Yates with a portable draw
    const std::size_t j = static_cast<std::size_t>(rng() % i);
    std::swap(candidates[i - 1], candidates[j]);
  }

  std::vector<RoundIncision> out;
  for (const SurfacePoint& s : candidates) {
    if (pattern.count && static_cast<int>(out.size()) >= *pattern.count) break;
    const bool far_enough = std::all_of(out.begin(), out.end(), [&](const RoundIncision& r) {
      return (r.centre_mm - s.position_mm).norm() >= pattern.spacing_mm;
    });
    if (!far_enough) continue;
    if (!rim_fits(surface, s, pattern.radius_mm)) continue;
    if (surface.thickness_mm(s.position_mm, -s.normal) + kDepthSlackCells * h < pattern.depth_mm) continue;
    out.push_back({s.position_mm, pattern.radius_mm, pattern.depth_mm, pattern.plug});
  }
  if (out.empty())
    throw InputError(fmt::format("no incision of radius {:.3g} mm and depth {:.3g} mm fits in the region ({} surface "
                                 "points there); expected a larger region, a smaller radius or a shallower depth",
                                 pattern.radius_mm, pattern.depth_mm, candidates.size()));
  if (pattern.count && static_cast<int>(out.size()) < *pattern.count)
    throw InputError(fmt::format("{} incisions asked for, but only {} fit at spacing {:.3g} mm; expected at most {} "
                                 "or a smaller spacing",
                                 *pattern.count, out.size(), pattern.spacing_mm, out.size()));
  return out;
}

}  // namespace cleave
