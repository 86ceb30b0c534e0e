#pragma once
// One level of the multigrid's linked-grid hierarchy: hexahedral cells on a uniform grid (the
// linked volume's cells on level 0, cells of twice the edge on each coarser level), the uncut
// links between face-adjacent cells, and the vertices shared by linked cells. A coarse cell may
// be one of several replicas of the same voxel (one per connected group of its fine cells), so a
// level's links are a list, not one slot per face.
//
//   GridLevel fine = grid_level_of(volume);    // level 0: ids are the volume's cells and vertices
#include <array>
#include <vector>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

/// An uncut link: cell `from` shares its face `face` with cell `to` (stored once per pair).
struct LevelLink {
  CellId from = kNone;
  CellId to = kNone;
  Face face = 0;
};

struct GridLevel {
  Vec3i dims{0, 0, 0};                              ///< voxels along x, y, z on this level
  std::vector<Vec3i> cell_voxel;                    ///< per cell: voxel at this level's resolution
  std::vector<std::array<VertexId, 8>> cell_vertices;  ///< per cell and corner (hex8 order)
  std::vector<LevelLink> links;                     ///< uncut links
  VertexId vertex_count = 0;

  CellId cell_count() const { return static_cast<CellId>(cell_voxel.size()); }
};

/// Level 0: the volume's cells, uncut links and current (split) vertices, ids unchanged.
GridLevel grid_level_of(const LinkedVolume& volume);

}  // namespace cleave
