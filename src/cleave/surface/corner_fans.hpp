#pragma once
// The fans of boundary faces around one grid corner: the topology of the render surface's
// vertices (dual contouring on the linked volume).
//
// A boundary face is a cell face whose link is absent or cut. Around each of its two edges
// through the corner, a boundary face is chained to one other boundary face of that grid edge
// (its partner), and following the chain around the corner gives closed fans; each fan becomes
// one surface vertex. Every face has exactly one partner across each edge and both ends of a
// grid edge use the same partners, so every surface edge is used by exactly two faces.
//
// Partners: around a grid edge, the runs of linked cells (sectors) are separated by cut or
// absent links. Normally a face is joined to the face at the other end of its own sector, found
// by walking from its cell through linked cells around the edge; cells that touch only along an
// edge or at a point become separate fans, and all cells of a fan share one linked-volume vertex.
// Where two or more sectors of one edge have the same linked-volume vertex at both ends of the
// edge (a slit whose mouth is a single grid edge between two crack tips, on the body's outside
// or on the wall of a hole left by a removed plug; two cells touching along an edge and joined
// at both its ends), they are all in one fan at each end, and material partners would give two
// surface edges between the same two vertices (4 triangles on one edge). Those sectors are
// joined across the gaps between them instead, in ring order (the end of each with the start of
// the next), as the simulation mesh holds them together along the edge; the fans at both ends
// split so that each pair has its own surface edge, and a fan's cells still share one vertex.
// Such a slit is closed at its mouth: a crack inside the body, a closed surface of its own.
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
