#include "bench_scenario.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cleave/core/error.hpp"
#include "cleave/cut/body_surface.hpp"

namespace cleave::bench {
namespace {

constexpr double kIncisionRadiusMm = 8.0;
constexpr double kMinIncisionRadiusCells = 1.5;
constexpr double kIncisionSpacingRadii = 4.0;
constexpr double kDepthFractionOfThickness = 0.5;
constexpr double kCutLengthFractionOfBody = 0.4;
constexpr double kLangerTension_kPa = 20.0;  // paper section 7: along Langer's lines
constexpr double kCrossTension_kPa = 10.0;   // across them

/// Direct residual stress: 20 kPa around the z axis through the body's centre (the tube's
/// circumference, the abdomen's horizontal direction), 10 kPa along z, none radially.
std::vector<Vec6> circumferential_stress(const TissueModel& model) {
  const auto [lo, hi] = model.bounding_box_mm();
  const Vec3 centre = 0.5 * (lo + hi);
  const LinkedVolume& volume = model.volume;
  std::vector<Vec6> stress(static_cast<std::size_t>(volume.cell_count()));
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    Vec3 radial = volume.cell_center_mm(c) - centre;
    radial.z() = 0;
    const Vec3 langer = radial.norm() > 0 ? Vec3(Vec3::UnitZ().cross(radial).normalized()) : Vec3(Vec3::UnitX());
    const Mat3 sigma = kLangerTension_kPa * langer * langer.transpose() +
                       kCrossTension_kPa * Vec3::UnitZ() * Vec3::UnitZ().transpose();
    stress[static_cast<std::size_t>(c)] = to_voigt(sigma);
  }
  return stress;
}

double incision_depth_mm(const BodySurface& surface, const SurfacePoint& at) {
  const double h = surface.cell_size_mm();
  const double thickness = surface.thickness_mm(at.position_mm, -at.normal);
  return std::clamp(kDepthFractionOfThickness * thickness, std::min(h, thickness), thickness);
}

CutRequests spread_incisions(const BodySurface& surface) {
  const double h = surface.cell_size_mm();
  const double radius = std::max(kIncisionRadiusMm, kMinIncisionRadiusCells * h);
  const double spacing = kIncisionSpacingRadii * radius;
  CutRequests accepted;
  std::vector<Vec3> centres;
  for (const SurfacePoint& s : surface.samples(SurfaceSide::outer)) {
    const bool crowded = std::any_of(centres.begin(), centres.end(),
                                     [&](const Vec3& c) { return (c - s.position_mm).norm() < spacing; });
    if (crowded) continue;
    CutRequests candidate;
    candidate.incisions.push_back({s.position_mm, radius, incision_depth_mm(surface, s), PlugHandling::remove});
    try {
      plan_cuts(surface, candidate);
    } catch (const InputError&) {
      continue;  // rim off the surface (the body's edges) or too thin here: not a place for an incision
    }
    centres.push_back(s.position_mm);
    accepted.incisions.push_back(candidate.incisions.front());
  }
  return accepted;
}

std::vector<ScalpelCut> ongoing_cut(const BodySurface& surface, const TissueModel& model, int segments) {
  const auto [lo, hi] = model.bounding_box_mm();
  const Vec3 centre = 0.5 * (lo + hi);
  const double length = kCutLengthFractionOfBody * (hi.z() - lo.z());
  const double far = hi.y() - lo.y();
  std::vector<Vec3> path;
  double depth = 0;
  for (int i = 0; i <= segments; ++i) {
    const double z = centre.z() - 0.5 * length + length * i / segments;
    const std::optional<SurfacePoint> top = surface.project(Vec3(centre.x(), hi.y(), z), far);
    if (!top) throw InputError(fmt::format("bench scenario: no surface above ({}, {}) mm for the scalpel cut", centre.x(), z));
    path.push_back(top->position_mm);
    if (i == segments / 2) depth = incision_depth_mm(surface, *top);
  }
  std::vector<ScalpelCut> cuts;
  for (int i = 0; i < segments; ++i) cuts.push_back({{path[static_cast<std::size_t>(i)], path[static_cast<std::size_t>(i) + 1]}, depth, 0.0});
  return cuts;
}

}  // namespace

BenchScenario make_bench_scenario(const TissueModel& model, const ScenarioOptions& options) {
  const BodySurface surface(model);
  BenchScenario s;
  s.residual_stress_kPa = circumferential_stress(model);
  s.incisions = spread_incisions(surface);
  if (s.incisions.incisions.empty())
    throw InputError(fmt::format("bench scenario: no round incision fits on the surface of {}", model.source));
  s.cut_segments = ongoing_cut(surface, model, std::max(options.cut_segments, 1));
  return s;
}

}  // namespace cleave::bench
