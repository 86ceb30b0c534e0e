#pragma once
// Eigenvalue control points to per-cell targets of the eigenvalue interpolation (eq. 8): each
// point is snapped onto the body surface (surface_cells.hpp) and prescribes, at that boundary
// cell, lambda = (langer, cross, 0) kPa (the normal eigenvalue is 0 on the free surface).
//
//   std::vector<EigenvalueTarget> t = control_point_targets(model, design.control_points, tol_mm);
//
// InputError (prefixed by `label`) for: no control points at all ("...; expected at least one
// control point: without one the eigenvalue field would silently be zero"), non-finite values,
// or a point farther than `tolerance_mm` from the surface (naming its index and distance).
#include <string>
#include <vector>

#include "cleave/model/tissue_model.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave {

struct EigenvalueTarget {
  CellId cell = kNone;
  Vec3 eigenvalues_kPa = Vec3::Zero();  ///< Langer, cross, normal
};

std::vector<EigenvalueTarget> control_point_targets(const TissueModel& model,
                                                    const std::vector<DesignControlPoint>& control_points,
                                                    double tolerance_mm, const std::string& label = "design control point");

}  // namespace cleave
