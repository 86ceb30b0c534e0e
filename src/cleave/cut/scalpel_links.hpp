#pragma once
// The links a scalpel cut severs: the path is snapped onto the surface and resampled every half
// cell; at each sample the blade points along the inward normal, tilted by the blade angle about
// the path's tangent; the blade sweeps a ruled surface from one cell above the skin down to the
// cut's depth. Links whose dual segments cross that surface are cut.
//
//   SweptPath path = sweep_path(surface, cut, tolerance_mm);   // throws InputError off the surface
//   std::vector<CellFace> links = scalpel_links(model.volume, path, cut.depth_mm);
#include <vector>

#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/cut_requests.hpp"
#include "cleave/cut/links_crossing_surface.hpp"

namespace cleave {

struct SweptPath {
  std::vector<Vec3> skin_mm;  ///< samples on the surface, about half a cell apart
  std::vector<Vec3> normal;   ///< outward unit surface normal per sample
  std::vector<Vec3> blade;    ///< unit sweep direction per sample (inward, tilted by the blade angle)
  double length_mm = 0;       ///< along the samples
};

/// Snaps and resamples `path_mm` (polyline; `closed` joins the last point to the first). Throws
/// InputError naming the point when a path point lies farther than `tolerance_mm` from the
/// surface.
SweptPath sweep_path(const BodySurface& surface, const std::vector<Vec3>& path_mm, double blade_angle_deg,
                     double tolerance_mm, bool closed);

/// Triangles of the ruled surface swept by `path` from one cell above the skin to `depth_mm`.
std::vector<Triangle> swept_triangles(const SweptPath& path, double depth_mm, double cell_size_mm);

/// Uncut links crossing the swept surface.
std::vector<CellFace> scalpel_links(const LinkedVolume& volume, const SweptPath& path, double depth_mm);

}  // namespace cleave
