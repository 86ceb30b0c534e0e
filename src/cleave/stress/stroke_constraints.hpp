#pragma once
// From what the user drew to per-cell targets of the direction interpolation (paper section 4,
// eqs. 7 to 9 for eigenvectors). Directions are lines, not arrows: a target is the unit-trace
// tensor t t^T (or n n^T), identical for t and -t, so the drawing direction of a stroke never
// matters (issue 4, item 2).
//
//   std::vector<LineTarget> t = stroke_line_targets(model, design.strokes, tolerance_mm);
//   std::vector<LineTarget> n = surface_normal_targets(model);
//
// Strokes are sampled every < half a cell. Surface strokes: every sample is snapped to the
// nearest open face (surface_cells.hpp) and constrains that boundary cell; a drawn point farther
// than `tolerance_mm` from the surface is an InputError naming the stroke and point, e.g.
//   "design stroke 2 point 5 at (1, 2, 3) mm is 7.3 mm from the body surface; expected within 5 mm".
// Interior strokes: samples constrain the cell containing them; a drawn point outside the body is
// an InputError naming it. Strokes with fewer than 2 points, non-finite coordinates or zero length
// are InputErrors too.
#include <string>
#include <vector>

#include "cleave/model/tissue_model.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave {

/// A line-direction target at one cell: the mean of the unit line tensors d d^T of the samples in
/// that cell (trace 1; rank 1 when all samples agree).
struct LineTarget {
  CellId cell = kNone;
  Mat3 tensor = Mat3::Zero();
};

/// Targets for the Langer direction from the strokes, sorted by cell id (one per cell).
/// `label` prefixes messages (e.g. "case.json: /design/strokes" or "design stroke").
std::vector<LineTarget> stroke_line_targets(const TissueModel& model, const std::vector<DesignStroke>& strokes,
                                            double tolerance_mm, const std::string& label = "design stroke");

/// Targets for the normal direction: n n^T at every boundary cell (surface_normal), by cell id.
std::vector<LineTarget> surface_normal_targets(const TissueModel& model);

/// Distance (mm) from p to the nearest open-face centre of the body (for messages); infinity
/// for a body without open faces.
double distance_to_surface_mm(const LinkedVolume& volume, const Vec3& p_mm);

}  // namespace cleave
