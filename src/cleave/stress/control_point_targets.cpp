#include "cleave/stress/control_point_targets.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/stress/stroke_constraints.hpp"
#include "cleave/stress/surface_cells.hpp"

namespace cleave {

std::vector<EigenvalueTarget> control_point_targets(const TissueModel& model,
                                                    const std::vector<DesignControlPoint>& control_points,
                                                    double tolerance_mm, const std::string& label) {
  if (control_points.empty())
    throw InputError(fmt::format("{}s: the design has none; expected at least one control point with the Langer and "
                                 "cross eigenvalues (kPa), without which the stress would silently be zero",
                                 label));
  std::vector<EigenvalueTarget> targets;
  targets.reserve(control_points.size());
  for (std::size_t i = 0; i < control_points.size(); ++i) {
    const DesignControlPoint& cp = control_points[i];
    if (!cp.position_mm.allFinite())
      throw InputError(fmt::format("{} {} position is not finite; expected coordinates in mm", label, i));
    if (!std::isfinite(cp.langer_kPa) || !std::isfinite(cp.cross_kPa))
      throw InputError(fmt::format("{} {} eigenvalues ({}, {}) are not finite; expected stresses in kPa", label, i,
                                   cp.langer_kPa, cp.cross_kPa));
    const SurfaceSnap snap = snap_to_surface(model.volume, cp.position_mm, tolerance_mm);
    if (snap.cell == kNone)
      throw InputError(fmt::format("{} {} at ({:.6g}, {:.6g}, {:.6g}) mm is {:.3g} mm from the body surface; expected within {:.3g} mm",
                                   label, i, cp.position_mm.x(), cp.position_mm.y(), cp.position_mm.z(),
                                   distance_to_surface_mm(model.volume, cp.position_mm), tolerance_mm));
    targets.push_back({snap.cell, Vec3(cp.langer_kPa, cp.cross_kPa, 0.0)});
  }
  return targets;
}

}  // namespace cleave
