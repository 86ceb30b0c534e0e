#pragma once
// The fans of boundary faces around one grid corner: the topology of the render surface's
// vertices (dual contouring on the linked volume).
//
// A boundary face is a cell face whose link is absent or cut. Around each of its two edges
// through the corner, a boundary face is chained to the next boundary face met by walking from
// its cell through linked cells around that edge. Following the chain around the corner gives
// closed fans; each fan becomes one surface vertex. Because the walk only crosses linked faces,
// all cells of a fan share one linked-volume vertex, and because every face has exactly one
// successor across each edge, every surface edge is used by exactly two faces (also where cells
// touch only along an edge or at a point: those become separate fans).
#include <array>
#include <vector>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

/// One fan: the boundary faces around a grid corner that form one surface vertex, in order.
struct CornerFan {
  static constexpr int kMaxFaces = 24;  ///< 8 cells x 3 faces at a corner
  std::array<CellFace, kMaxFaces> faces{};
  std::array<int, kMaxFaces> cell_corner{};  ///< which corner (0..7) of faces[i].cell the grid corner is
  int count = 0;
};

/// All fans at grid corner `g` (0..dims per axis), in a deterministic order (by the lowest
/// cell-octant and face axis that starts them). Empty when no boundary face touches `g`.
std::vector<CornerFan> corner_fans(const LinkedVolume& volume, const Vec3i& g);

/// True when face f of cell c is on the render surface (no neighbour, or the link is cut).
inline bool is_boundary_face(const LinkedVolume& volume, CellId c, Face f) { return !volume.linked(c, f); }

/// Position (0..3) of cell corner `corner` in the counter-clockwise (seen from outside) quad of
/// face f, or -1 when the corner is not on that face.
int quad_slot(Face f, int corner);

/// Cell corner (0..7) at position `slot` (0..3) of the counter-clockwise quad of face f.
int quad_corner(Face f, int slot);

}  // namespace cleave
