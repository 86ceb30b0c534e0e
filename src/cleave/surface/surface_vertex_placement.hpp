#pragma once
// Where a render-surface vertex goes: the sub-cell position of a fan's vertex (dual contouring)
// and the hex cell + local coordinates that embed it.
//
// The smooth surface is the zero level set of a field sampled at grid corners (mm, negative
// inside): LabelVolume::corner_distance_mm when the model has it, otherwise the smoothed
// occupancy distance of mask_distance_field. A vertex whose fan holds at least one face on the
// body's outside takes Newton steps towards the zero level set (trilinear interpolation of the
// corner field), clamped to its dual cell (at most `max_shift` cell sizes from the grid corner per
// axis). Axes normal to cut faces of the fan stay fixed, so a cut rim moves within the cut plane
// and both sides of a cut stay together; fans made only of cut faces stay on the grid corner.
#include <vector>

#include "cleave/grid/label_volume.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/surface/corner_fans.hpp"

namespace cleave {

/// Per-axis clamp (cell sizes) of a vertex's move for a signed distance field: the dual cell.
inline constexpr double kDistanceFieldMaxShiftCells = 0.5;
/// Per-axis clamp (cell sizes) for the smoothed occupancy of a voxel mask (a light smoothing
/// that keeps quads from collapsing on one-voxel features).
inline constexpr double kMaskFieldMaxShiftCells = 0.25;

/// The field the surface is the zero level set of, as a view on corner values.
struct SurfaceField {
  const GridSpec* grid = nullptr;
  const std::vector<float>* corner_mm = nullptr;  ///< one per grid corner (grid->corner_index)
  double max_shift_cells = kDistanceFieldMaxShiftCells;

  /// Trilinear interpolation at p (mm); p is clamped to the grid's box.
  double sample_mm(const Vec3& p_mm) const;
};

/// Smoothed occupancy distance of a voxel mask at every grid corner (mm, negative inside):
/// h (1 - 2 o) where o is the fraction of the 8 voxels around the corner that are inside. It is
/// 0 on flat voxel faces, +-h one cell off them, so its zero level set is the voxel boundary with
/// edges and corners rounded.
std::vector<float> mask_distance_field(const LabelVolume& labels);

struct VertexPlacement {
  Vec3 position_mm = Vec3::Zero();
  CellId cell = kNone;  ///< one of the fan's cells: the one whose box is closest to the position
  Vec3 xi = Vec3::Zero();  ///< position = cell minimum corner + h xi
};

/// Position and embedding of the surface vertex of `fan` at grid corner g.
VertexPlacement place_fan_vertex(const LinkedVolume& volume, const SurfaceField& field, const Vec3i& g,
                                 const CornerFan& fan);

}  // namespace cleave
