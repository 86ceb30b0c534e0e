#pragma once
// The render surface (paper section 6, after Wu, Dick & Westermann 2011): a smooth, closed,
// consistently oriented triangle surface of the body that is topologically consistent with the
// linked volume, built by dual contouring on it.
//
// Construction
//   - One quad per boundary face: a cell face whose link is absent (the body's outside) or cut.
//     Both sides of a cut face are boundary faces of their own cells, so a cut opens the surface
//     and two pieces give two separate closed surfaces. Quads are oriented with the outward
//     normal of their cell (counter-clockwise seen from outside) and split into two triangles
//     along the shorter diagonal of the reference positions (on a cut face, never along a
//     diagonal whose ends the face shares with its opposite face at a crack front).
//   - Surface vertices are the fans of boundary faces around a grid corner (corner_fans.hpp):
//     faces are chained across each edge by walking through linked material, so every surface
//     edge is used by exactly two triangles and every vertex is a single disk, also where cells
//     touch only along an edge or at a point. All cells of a fan share one linked-volume vertex;
//     a split linked-volume vertex always gives separate surface vertices. Where the linked
//     volume holds two runs of cells around a grid edge together at both its ends (a one-cell
//     slit between two crack tips), the surface joins them along that edge too.
//   - Positions (surface_vertex_placement.hpp): vertices on the body's outside move to the zero
//     crossing of the corner signed distance (LabelVolume::corner_distance_mm) within their dual
//     cell, or of a smoothed occupancy when the model is a voxel mask; vertices on a cut rim move
//     only within the cut planes; vertices inside a cut stay on the grid corner.
//   - Embedding: every vertex has a cell of its fan and local coordinates xi (position =
//     cell's minimum corner + h xi). xi lies in [0,1]^3 when the vertex is inside that cell; a
//     vertex of the smooth surface that lies just outside the voxelized body (at most half a cell,
//     the dual-cell clamp) has xi in [-0.5, 1.5]^3 and follows the cell by trilinear extrapolation.
//
//   RenderSurface s = build_render_surface(model);
//   CutReport r = model.volume.cut_links(links);
//   update_render_surface(s, model, r);                        // same result as a new build
//   std::vector<Vec3> x = deformed_positions(s, model.volume, displacement_mm);
#include <array>
#include <cstdint>
#include <vector>

#include "cleave/model/tissue_model.hpp"

namespace cleave {

using SurfaceVertexId = std::int32_t;

/// One boundary face of the linked volume and its quad of surface vertices.
struct SurfaceQuad {
  CellId cell = kNone;  ///< the cell whose face this is (the surface's inside)
  Face face = 0;        ///< 0..5, see linked_volume.hpp; the outward normal is face_step(face)
  bool is_cut = false;  ///< true on a cut face (the neighbour exists but the link is cut)
  /// Surface vertices, counter-clockwise seen from outside.
  std::array<SurfaceVertexId, 4> vertices{kNone, kNone, kNone, kNone};
  /// Triangles (0,1,2)+(0,2,3) when 0, (0,1,3)+(1,2,3) when 1.
  std::uint8_t diagonal = 0;
};

struct RenderSurface {
  // Per surface vertex -------------------------------------------------------------------------
  std::vector<Vec3> reference_mm;  ///< position in the reference (undeformed) configuration
  std::vector<CellId> cell;        ///< embedding cell (one of the cells of the vertex's fan)
  std::vector<Vec3> xi;            ///< local coordinates in that cell (see header comment)
  std::vector<Vec3i> grid_corner;  ///< grid corner the vertex belongs to

  // Per boundary face (quad q gives triangles 2q and 2q+1) ---------------------------------------
  std::vector<SurfaceQuad> quads;
  std::vector<std::array<SurfaceVertexId, 3>> triangles;  ///< counter-clockwise seen from outside

  /// Quad index per cell face (6 * cell + face), kNone where the face is not on the surface.
  std::vector<std::int32_t> quad_of_face;
  /// Smoothed occupancy distance per grid corner (mm) for voxel-mask models; empty when the
  /// model has corner_distance_mm.
  std::vector<float> mask_distance_mm;

  SurfaceVertexId vertex_count() const { return static_cast<SurfaceVertexId>(reference_mm.size()); }
  std::int32_t triangle_count() const { return static_cast<std::int32_t>(triangles.size()); }
  /// The boundary face triangle t came from.
  const SurfaceQuad& quad_of_triangle(std::int32_t t) const { return quads[static_cast<size_t>(t / 2)]; }
  CellId triangle_cell(std::int32_t t) const { return quad_of_triangle(t).cell; }
  Face triangle_face(std::int32_t t) const { return quad_of_triangle(t).face; }
  bool triangle_is_cut(std::int32_t t) const { return quad_of_triangle(t).is_cut; }
};

/// Builds the render surface of `model` in its current cut state. Cost: linear in the number of
/// cells (about 35 ms of CPU time for the 45,000-cell abdomen).
RenderSurface build_render_surface(const TissueModel& model);

/// Updates `surface` (built from `model` before the cut) after `model.volume.cut_links` returned
/// `report`: only the boundary faces at the corners of report.touched_cells are rebuilt. The
/// result equals build_render_surface(model) up to the order of vertices and quads. Several cuts
/// between two updates need their reports merged (touched_cells of all of them).
/// Throws ComputeError when `surface` does not belong to `model`.
void update_render_surface(RenderSurface& surface, const TissueModel& model, const CutReport& report);

/// Surface vertex positions (mm) for a displacement field on the linked volume's vertices:
/// trilinear interpolation of the 8 vertex displacements of each vertex's embedding cell.
/// `displacement_mm` has one entry per linked-volume vertex, or is empty (reference positions).
/// Throws InputError when its size does not match the volume's vertex count.
std::vector<Vec3> deformed_positions(const RenderSurface& surface, const LinkedVolume& volume,
                                     const std::vector<Vec3>& displacement_mm);

}  // namespace cleave
