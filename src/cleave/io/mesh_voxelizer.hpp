#pragma once
// Voxelizing a closed triangle surface onto cleave's grid with OpenVDB (robust to small holes,
// self-intersections, non-manifold bits and inconsistent triangle orientation).
#include <optional>
#include <string>

#include "cleave/core/progress.hpp"
#include "cleave/grid/label_volume.hpp"
#include "cleave/io/surface_mesh_file.hpp"

namespace cleave {

struct MeshVoxelizeOptions {
  /// Cell edge (mm); default: the mesh's largest bounding-box extent / 64.
  std::optional<double> cell_size_mm;
  std::string source = "mesh";  ///< the file name, for error messages
  ProgressFn progress;
};

/// Cells along the largest extent when no cell size is given.
inline constexpr int kDefaultMeshCellsAlongLargestExtent = 64;

/// Signed distance field of the surface (OpenVDB meshToLevelSet on a grid of half the cell size,
/// so that cell centres and grid corners are both exact samples). A cell is inside (label 1) when
/// the distance at its centre is negative; corner_distance_mm holds the distance at every grid
/// corner (mm, negative inside, clamped to +-1.5 cells away from the surface). The grid covers
/// the mesh's bounding box plus one empty cell on every side.
/// Throws InputError naming options.source: empty mesh, non-positive cell size, a grid that would
/// not fit in memory (before voxelizing), or a surface that encloses nothing: no cell centre half
/// a cell deep inside, or an inside region whose boundary mostly lies away from the triangles
/// (open, flat or degenerate surfaces: "encloses no volume").
LabelVolume voxelize_surface_mesh(const TriangleMesh& mesh, const MeshVoxelizeOptions& options);

}  // namespace cleave
