#pragma once
// The body surface as the design sees it: boundary cells (cells with a face that has no linked
// neighbour: outside the body or across a cut), their outward surface normal, and snapping a
// point onto the surface (paper section 6: values painted on the surface go to the closest cells).
//
//   SurfaceSnap s = snap_to_surface(model, p_mm, 2.0 * h);   // s.cell == kNone when too far
//   std::optional<Vec3> n = surface_normal(model, cell);      // unit, outward; nullopt inside
//
// The snap is the nearest centre of a boundary face (a cell face without a linked neighbour),
// searched in the voxels within the tolerance of p; this is the one place to switch to the render
// surface's closest point later.
#include <optional>
#include <vector>

#include "cleave/model/tissue_model.hpp"

namespace cleave {

/// True when at least one face of c has no linked neighbour.
bool is_boundary_cell(const LinkedVolume& volume, CellId c);

/// All boundary cells, in increasing id.
std::vector<CellId> boundary_cells(const LinkedVolume& volume);

/// Outward unit normal of the surface at boundary cell c: the gradient of the corner signed
/// distance (LabelVolume::corner_distance_mm) at the cell centre when present and non-zero, else
/// the principal direction of the open faces' normals (sum of f f^T), oriented by their sum.
/// nullopt for interior cells.
std::optional<Vec3> surface_normal(const TissueModel& model, CellId c);

struct SurfaceSnap {
  CellId cell = kNone;           ///< boundary cell of the nearest open face; kNone when none within tolerance
  Vec3 point_mm = Vec3::Zero();  ///< centre of that face
  double distance_mm = 0;        ///< |p - point| (infinity when no face was within tolerance)
};

/// Nearest open-face centre within `tolerance_mm` of p (ties: lowest cell id, then face).
SurfaceSnap snap_to_surface(const LinkedVolume& volume, const Vec3& p_mm, double tolerance_mm);

}  // namespace cleave
