#include "bench_scenario.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cleave/core/error.hpp"
#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/place_incisions.hpp"
#include "cleave/stress/stress_designer.hpp"

namespace cleave::bench {
namespace {

constexpr double kIncisionRadiusMm = 8.0;
constexpr double kMinIncisionRadiusCells = 1.5;
constexpr double kIncisionSpacingRadii = 4.0;
constexpr double kDepthFractionOfThickness = 0.5;
constexpr double kCutLengthFractionOfBody = 0.4;
constexpr double kLangerTension_kPa = 20.0;  // paper section 7: along Langer's lines
constexpr double kCrossTension_kPa = 10.0;   // across them
constexpr double kStrokeWidthFraction = 0.7; // of the body's x extent
constexpr int kStrokePoints = 16;
constexpr double kControlPointOffsetFraction = 0.25;  // of the extent, from the centre

double incision_depth_mm(const BodySurface& surface, const SurfacePoint& at) {
  const double h = surface.cell_size_mm();
  const double thickness = surface.thickness_mm(at.position_mm, -at.normal);
  return std::clamp(kDepthFractionOfThickness * thickness, std::min(h, thickness), thickness);
}

/// The surface point on top of the body (largest y) above (x, z), or InputError.
SurfacePoint top_point(const BodySurface& surface, const TissueModel& model, double x_mm, double z_mm) {
  const auto [lo, hi] = model.bounding_box_mm();
  const std::optional<SurfacePoint> top = surface.project(Vec3(x_mm, hi.y(), z_mm), hi.y() - lo.y());
  if (!top) throw InputError(fmt::format("bench scenario: no surface above ({}, {}) mm of {}", x_mm, z_mm, model.source));
  return *top;
}

CutRequests spread_incisions(const BodySurface& surface, const TissueModel& model) {
  const auto [lo, hi] = model.bounding_box_mm();
  const Vec3 centre = 0.5 * (lo + hi);
  IncisionPattern pattern;
  pattern.radius_mm = std::max(kIncisionRadiusMm, kMinIncisionRadiusCells * surface.cell_size_mm());
  pattern.spacing_mm = kIncisionSpacingRadii * pattern.radius_mm;
  pattern.depth_mm = incision_depth_mm(surface, top_point(surface, model, centre.x(), centre.z()));
  CutRequests requests;
  // place_incisions may accept a rim that plan_cuts then refuses near the body's ends (reported
  // to the cut owner); keep only incisions the cut plan accepts.
  for (const RoundIncision& incision : place_incisions(surface, pattern)) {
    CutRequests one;
    one.incisions.push_back(incision);
    try {
      plan_cuts(surface, one);
    } catch (const InputError&) {
      continue;
    }
    requests.incisions.push_back(incision);
  }
  return requests;
}

std::vector<ScalpelCut> ongoing_cut(const BodySurface& surface, const TissueModel& model, int segments) {
  const auto [lo, hi] = model.bounding_box_mm();
  const Vec3 centre = 0.5 * (lo + hi);
  const double length = kCutLengthFractionOfBody * (hi.z() - lo.z());
  std::vector<Vec3> path;
  double depth = 0;
  for (int i = 0; i <= segments; ++i) {
    const double z = centre.z() - 0.5 * length + length * i / segments;
    const SurfacePoint top = top_point(surface, model, centre.x(), z);
    path.push_back(top.position_mm);
    if (i == segments / 2) depth = incision_depth_mm(surface, top);
  }
  std::vector<ScalpelCut> cuts;
  for (int i = 0; i < segments; ++i) cuts.push_back({{path[static_cast<std::size_t>(i)], path[static_cast<std::size_t>(i) + 1]}, depth, 0.0});
  return cuts;
}

DesignStroke stroke_across_top(const BodySurface& surface, const TissueModel& model, double z_mm) {
  const auto [lo, hi] = model.bounding_box_mm();
  const double half_width = 0.5 * kStrokeWidthFraction * (hi.x() - lo.x());
  const double centre_x = 0.5 * (lo.x() + hi.x());
  DesignStroke stroke;
  for (int i = 0; i < kStrokePoints; ++i) {
    const double x = centre_x - half_width + 2.0 * half_width * i / (kStrokePoints - 1);
    stroke.points_mm.push_back(top_point(surface, model, x, z_mm).position_mm);
  }
  return stroke;
}

StressDesign bench_design(const BodySurface& surface, const TissueModel& model) {
  const auto [lo, hi] = model.bounding_box_mm();
  const Vec3 centre = 0.5 * (lo + hi);
  const Vec3 extent = hi - lo;
  StressDesign design;
  design.strokes.push_back(stroke_across_top(surface, model, lo.z() + extent.z() / 3.0));
  design.strokes.push_back(stroke_across_top(surface, model, lo.z() + 2.0 * extent.z() / 3.0));
  const double dx = kControlPointOffsetFraction * extent.x(), dz = kControlPointOffsetFraction * extent.z();
  for (const auto& [x, z] : {std::pair{centre.x(), centre.z()}, {centre.x() - dx, centre.z() - dz}, {centre.x() + dx, centre.z() - dz},
                             {centre.x() - dx, centre.z() + dz}, {centre.x() + dx, centre.z() + dz}})
    design.control_points.push_back({top_point(surface, model, x, z).position_mm, kLangerTension_kPa, kCrossTension_kPa});
  return design;
}

}  // namespace

std::vector<Vec6> prescribed_biaxial_stress(const TissueModel& model, double along_kPa, double axial_kPa) {
  const auto [lo, hi] = model.bounding_box_mm();
  const Vec3 centre = 0.5 * (lo + hi);
  const Vec3 axis = Vec3::UnitZ();
  const CellId cells = model.volume.cell_count();
  std::vector<Vec6> stress(static_cast<std::size_t>(cells));
  for (CellId c = 0; c < cells; ++c) {
    const Vec3 p = model.volume.cell_center_mm(c);
    const Vec3 circumferential(-(p.y() - centre.y()), p.x() - centre.x(), 0.0);
    const double r = circumferential.norm();
    Mat3 s = axial_kPa * axis * axis.transpose();
    if (r > 0) s += along_kPa * (circumferential / r) * (circumferential / r).transpose();
    stress[static_cast<std::size_t>(c)] = to_voigt(s);
  }
  return stress;
}

BenchScenario make_bench_scenario(const TissueModel& model, const ScenarioOptions& options) {
  const BodySurface surface(model);
  BenchScenario s;
  s.design = bench_design(surface, model);
  const auto [lo, hi] = model.bounding_box_mm();
  const double stroke_z_mm = lo.z() + (hi.z() - lo.z()) / 3.0;
  for (int i = 1; i <= 2; ++i) s.edited_strokes.push_back(stroke_across_top(surface, model, stroke_z_mm + i * surface.cell_size_mm()));
  for (int i = 1; i <= kDragEdits && stroke_z_mm - (i + 1) * surface.cell_size_mm() > lo.z(); ++i)
    s.dragged_strokes.push_back(stroke_across_top(surface, model, stroke_z_mm - i * surface.cell_size_mm()));
  s.designed_stress = options.designed_stress;
  s.residual_stress_kPa = s.designed_stress ? design_residual_stress(model, s.design).stress_kPa
                                            : prescribed_biaxial_stress(model, kLangerTension_kPa, kCrossTension_kPa);
  s.incisions = spread_incisions(surface, model);
  if (s.incisions.incisions.empty())
    throw InputError(fmt::format("bench scenario: no round incision fits on the surface of {}", model.source));
  s.cut_segments = ongoing_cut(surface, model, std::max(options.cut_segments, 1));
  return s;
}

}  // namespace cleave::bench
