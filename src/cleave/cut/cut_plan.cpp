#include "cleave/cut/cut_plan.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

constexpr int kRimChecks = 16;                  ///< rim points checked to lie on the surface
constexpr double kRimNormalAgreement = 0.5;     ///< least cosine between rim and centre normals
constexpr double kDepthSlackCells = 0.5;        ///< depth may exceed the measured thickness by this
constexpr double kMinPathLengthCells = 0.5;
constexpr double kMaxBladeAngleDeg = 90.0;

void require_positive_depth(double depth_mm, const std::string& who) {
  if (!(depth_mm > 0) || !std::isfinite(depth_mm))
    throw InputError(fmt::format("{}: depth {} mm; expected a positive depth in mm", who, depth_mm));
}

void require_within_thickness(double depth_mm, double thickness_mm, double h, const std::string& who) {
  if (depth_mm > thickness_mm + kDepthSlackCells * h)
    throw InputError(fmt::format("{}: depth {:.3g} mm is beyond the body's thickness there ({:.3g} mm); expected at "
                                 "most {:.3g} mm",
                                 who, depth_mm, thickness_mm, thickness_mm));
}

IncisionFrame checked_incision(const BodySurface& surface, const RoundIncision& in, double tol, const std::string& who) {
  const double h = surface.cell_size_mm();
  const double body_mm = surface.model().size_mm();
  if (!(in.radius_mm >= h) || !std::isfinite(in.radius_mm))
    throw InputError(fmt::format("{}: radius {} mm; expected at least one cell ({:.3g} mm)", who, in.radius_mm, h));
  if (2 * in.radius_mm >= body_mm)
    throw InputError(fmt::format("{}: radius {:.3g} mm makes the incision larger than the body ({:.3g} mm across); "
                                 "expected a diameter below that",
                                 who, in.radius_mm, body_mm));
  require_positive_depth(in.depth_mm, who);
  IncisionFrame frame;
  try {
    frame = incision_frame(surface, in, tol);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", who, e.what()));
  }
  for (int k = 0; k < kRimChecks; ++k) {
    const Vec3 p = frame.rim_point(2 * std::numbers::pi * k / kRimChecks, 0.0);
    const auto q = surface.project(p, h + in.radius_mm * (1 - std::cos(std::numbers::pi / 4)));
    if (!q || q->normal.dot(frame.normal) < kRimNormalAgreement)
      throw InputError(fmt::format("{}: radius {:.3g} mm at ({:.3g}, {:.3g}, {:.3g}) mm reaches off the body's "
                                   "surface; expected an incision that fits on the body",
                                   who, in.radius_mm, frame.centre_mm.x(), frame.centre_mm.y(), frame.centre_mm.z()));
  }
  require_within_thickness(in.depth_mm, surface.thickness_mm(frame.centre_mm, -frame.normal), h, who);
  return frame;
}

double min_thickness(const BodySurface& surface, const SweptPath& path) {
  double t = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < path.skin_mm.size(); ++i) t = std::min(t, surface.thickness_mm(path.skin_mm[i], path.blade[i]));
  return t;
}

SweptPath checked_scalpel(const BodySurface& surface, const ScalpelCut& cut, double tol, const std::string& who) {
  const double h = surface.cell_size_mm();
  if (cut.path_mm.size() < 2)
    throw InputError(fmt::format("{}: path has {} point(s); expected at least 2", who, cut.path_mm.size()));
  if (!(std::abs(cut.blade_angle_deg) < kMaxBladeAngleDeg))
    throw InputError(fmt::format("{}: blade angle {} degrees; expected a tilt strictly between -90 and 90", who,
                                 cut.blade_angle_deg));
  require_positive_depth(cut.depth_mm, who);
  SweptPath path;
  try {
    path = sweep_path(surface, cut.path_mm, cut.blade_angle_deg, tol, /*closed=*/false);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", who, e.what()));
  }
  if (path.length_mm < kMinPathLengthCells * h)
    throw InputError(fmt::format("{}: path is {:.3g} mm long; expected at least half a cell ({:.3g} mm)", who,
                                 path.length_mm, kMinPathLengthCells * h));
  require_within_thickness(cut.depth_mm, min_thickness(surface, path), h, who);
  return path;
}

FlapRegion checked_flap(const BodySurface& surface, const Flap& flap, double tol, const std::string& who) {
  require_positive_depth(flap.depth_mm, who);
  FlapRegion region;
  try {
    region = flap_region(surface, flap, tol);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", who, e.what()));
  }
  double thickness = std::numeric_limits<double>::infinity();
  for (const Vec3& p : flap.path_mm)
    if (const auto s = surface.project(p, tol)) thickness = std::min(thickness, surface.thickness_mm(s->position_mm, -s->normal));
  require_within_thickness(flap.depth_mm, thickness, surface.cell_size_mm(), who);
  if (region.cells.empty())
    throw InputError(fmt::format("{}: the path encloses no cell above depth {:.3g} mm; expected a larger flap", who,
                                 flap.depth_mm));
  return region;
}

}  // namespace

std::vector<CellId> CutPlan::hidden_cells() const {
  std::vector<CellId> out;
  for (const CutStep& s : steps) out.insert(out.end(), s.hidden_cells.begin(), s.hidden_cells.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

CutPlan plan_cuts(const BodySurface& surface, const CutRequests& requests, double tolerance_mm,
                  const CutRequestNames& names) {
  const double tol = tolerance_mm > 0 ? tolerance_mm : kSurfaceToleranceCells * surface.cell_size_mm();
  const LinkedVolume& volume = surface.model().volume;
  CutPlan plan;
  for (std::size_t i = 0; i < requests.incisions.size(); ++i)
    plan.incisions.push_back(
        checked_incision(surface, requests.incisions[i], tol, fmt::format("{} {}", names.incision, i)));
  for (std::size_t i = 0; i < requests.scalpel_cuts.size(); ++i)
    plan.scalpel_paths.push_back(
        checked_scalpel(surface, requests.scalpel_cuts[i], tol, fmt::format("{} {}", names.scalpel, i)));
  for (std::size_t i = 0; i < requests.flaps.size(); ++i)
    plan.flaps.push_back(checked_flap(surface, requests.flaps[i], tol, fmt::format("{} {}", names.flap, i)));

  for (std::size_t i = 0; i < plan.incisions.size(); ++i) {
    const PlugHandling plug = requests.incisions[i].plug;
    IncisionLinks l = round_incision_links(volume, plan.incisions[i], plug);
    CutStep step{CutStep::Kind::incision, i, std::move(l.links), {}};
    if (plug == PlugHandling::remove) step.hidden_cells = std::move(l.plug_cells);
    plan.steps.push_back(std::move(step));
  }
  for (std::size_t i = 0; i < plan.scalpel_paths.size(); ++i)
    plan.steps.push_back(
        {CutStep::Kind::scalpel, i, scalpel_links(volume, plan.scalpel_paths[i], requests.scalpel_cuts[i].depth_mm), {}});
  for (std::size_t i = 0; i < plan.flaps.size(); ++i)
    plan.steps.push_back({CutStep::Kind::flap, i, flap_links(volume, plan.flaps[i]), {}});
  return plan;
}

CutReport apply_cut_plan(LinkedVolume& volume, const CutPlan& plan) {
  CutReport total;
  for (const CutStep& step : plan.steps) {
    CutReport r = volume.cut_links(step.links);
    total.links_cut += r.links_cut;
    total.splits.insert(total.splits.end(), r.splits.begin(), r.splits.end());
    total.touched_cells.insert(total.touched_cells.end(), r.touched_cells.begin(), r.touched_cells.end());
  }
  return total;
}

}  // namespace cleave
