#include "cleave/surface/corner_fans.hpp"

#include <bit>
#include <utility>

namespace cleave {
namespace {

/// Cell-local corners of face f on axis a, side s, as (u, v) bits of the two other axes
/// u = (a + 1) % 3, v = (a + 2) % 3 in the order (0,0), (1,0), (1,1), (0,1): counter-clockwise
/// seen from +a. The -a side uses the reverse order.
constexpr std::array<std::array<int, 2>, 4> kQuadUv = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};

int bit(int k, int axis) { return (k >> axis) & 1; }

/// Face of the cell in octant k (the cell having the corner as its corner k) on axis a through
/// the corner; it separates the cell from octant k ^ (1 << a).
Face face_of(int k, int a) { return 2 * a + bit(k, a); }

/// One boundary face at a grid corner: the face on axis a of the cell in octant k.
struct OctantFace {
  int k = -1;
  int a = -1;
  bool valid() const { return k >= 0; }
};

/// The 8 cells around grid corner g (octant k: the cell at voxel g - corner_offset(k)).
using CornerCells = std::array<CellId, 8>;

CornerCells cells_around(const LinkedVolume& volume, const Vec3i& g) {
  CornerCells cells{};
  for (int k = 0; k < kCornerCount; ++k) cells[static_cast<size_t>(k)] = volume.cell_at_voxel(g - corner_offset(k));
  return cells;
}

bool boundary(const LinkedVolume& volume, const CornerCells& cells, int k, int a) {
  const CellId c = cells[static_cast<size_t>(k)];
  return c != kNone && is_boundary_face(volume, c, face_of(k, a));
}

/// The boundary face that (k, a) is joined to across the grid edge on axis `edge` through
/// linked material: walk from cell k around the edge through linked cells (starting with cell
/// k's other face at the edge) until a face that is not linked.
OctantFace material_partner(const LinkedVolume& volume, const CornerCells& cells, int k, int a, int edge) {
  const int third = 3 - a - edge;
  int axis = third;
  int kk = k;
  while (volume.linked(cells[static_cast<size_t>(kk)], face_of(kk, axis))) {
    kk ^= 1 << axis;
    axis = axis == a ? third : a;
  }
  return {kk, axis};
}

/// Per octant and axis: a value for each boundary face at a corner.
template <typename T>
using PerOctantFace = std::array<std::array<T, 3>, 8>;

/// Partner of each boundary face across each of its two edges through the corner, indexed
/// [k][a][edge axis]; invalid where the material partner applies.
using PartnerOverrides = PerOctantFace<std::array<OctantFace, 3>>;

/// Follows the chains of boundary faces around the corner: from a face across one edge to its
/// partner, then across that face's other edge. `partner(k, a, edge)` must be an involution.
template <typename Partner>
std::vector<CornerFan> trace_fans(const LinkedVolume& volume, const CornerCells& cells, Partner&& partner) {
  PerOctantFace<bool> visited{};
  std::vector<CornerFan> fans;
  for (int k0 = 0; k0 < kCornerCount; ++k0)
    for (int a0 = 0; a0 < 3; ++a0) {
      if (visited[static_cast<size_t>(k0)][static_cast<size_t>(a0)] || !boundary(volume, cells, k0, a0)) continue;
      CornerFan fan;
      int k = k0;
      int a = a0;
      int edge = a0 == 0 ? 1 : 0;  // leave the first face across its lower-axis edge
      do {
        visited[static_cast<size_t>(k)][static_cast<size_t>(a)] = true;
        fan.faces[static_cast<size_t>(fan.count)] = CellFace{cells[static_cast<size_t>(k)], face_of(k, a)};
        fan.cell_corner[static_cast<size_t>(fan.count)] = k;
        ++fan.count;
        const OctantFace next = partner(k, a, edge);
        edge = 3 - next.a - edge;  // continue across the next face's other edge
        k = next.k;
        a = next.a;
      } while ((k != k0 || a != a0) && fan.count < CornerFan::kMaxFaces);
      fans.push_back(fan);
    }
  return fans;
}

/// One run of linked cells around a grid edge, from the boundary face where it starts to the
/// one where it ends (in the ring order of the edge).
struct Sector {
  OctantFace start;
  OctantFace end;
};

/// Partners that replace the material ones around the grid edges through g. Material pairing
/// joins the two boundary faces at the ends of each run of linked cells around an edge (a
/// sector). Where two or more sectors have the same linked-volume vertex at both ends of the
/// edge, their surface edges would join the same two surface vertices (the sectors are in one
/// fan at each end: within one vertex group the fans are the loops around the void components,
/// and the void is joined through the edge). Such sectors are joined across the gaps between
/// them instead, in ring order: the end of each with the start of the next. The simulation mesh
/// holds them together along the edge, and the fans at both ends split so that each pair gets
/// its own surface edge. The rule reads only the cells around the edge and their vertices, so
/// both ends of the edge choose the same pairs.
PartnerOverrides edge_overrides(const LinkedVolume& volume, const CornerCells& cells) {
  PartnerOverrides overrides{};
  PerOctantFace<bool> on_surface{};
  for (int k = 0; k < kCornerCount; ++k)
    for (int a = 0; a < 3; ++a) on_surface[static_cast<size_t>(k)][static_cast<size_t>(a)] = boundary(volume, cells, k, a);
  for (int e = 0; e < 3; ++e)
    for (int side = 0; side < 2; ++side) {
      // The 4 octants around the edge from g along axis e (towards +e for side 0), in ring order.
      const int u = (e + 1) % 3;
      const int v = (e + 2) % 3;
      std::array<int, 4> ring{};
      for (size_t i = 0; i < 4; ++i) ring[i] = (side << e) | (kQuadUv[i][0] << u) | (kQuadUv[i][1] << v);
      // A sector ends where the face towards the next octant in the ring is on the surface.
      std::array<OctantFace, 4> ends_at{};
      size_t count = 0;
      for (size_t i = 0; i < 4; ++i) {
        const int k = ring[i];
        const int axis = std::countr_zero(static_cast<unsigned>(k ^ ring[(i + 1) % 4]));
        if (on_surface[static_cast<size_t>(k)][static_cast<size_t>(axis)]) ends_at[count++] = {k, axis};
      }
      if (count < 2) continue;
      std::array<Sector, 4> sectors{};
      for (size_t i = 0; i < count; ++i)
        sectors[i] = {material_partner(volume, cells, ends_at[i].k, ends_at[i].a, e), ends_at[i]};
      // Linked-volume vertices of a sector at this corner and at the other end of the edge.
      const auto ends = [&](const Sector& s) {
        const CellId c = cells[static_cast<size_t>(s.end.k)];
        return std::pair{volume.corner_vertex(c, s.end.k), volume.corner_vertex(c, s.end.k ^ (1 << e))};
      };
      std::array<bool, 4> grouped{};
      for (size_t i = 0; i < count; ++i) {
        if (grouped[i]) continue;
        std::array<size_t, 4> group{};
        size_t members = 0;
        for (size_t j = i; j < count; ++j)
          if (!grouped[j] && ends(sectors[j]) == ends(sectors[i])) {
            grouped[j] = true;
            group[members++] = j;
          }
        for (size_t m = 0; members > 1 && m < members; ++m) {
          const OctantFace end = sectors[group[m]].end;
          const OctantFace start = sectors[group[(m + 1) % members]].start;
          overrides[static_cast<size_t>(end.k)][static_cast<size_t>(end.a)][static_cast<size_t>(e)] = start;
          overrides[static_cast<size_t>(start.k)][static_cast<size_t>(start.a)][static_cast<size_t>(e)] = end;
        }
      }
    }
  return overrides;
}

}  // namespace

int quad_corner(Face f, int slot) {
  const int a = f / 2;
  const int side = f & 1;
  const int u = (a + 1) % 3;
  const int v = (a + 2) % 3;
  const auto& uv = kQuadUv[static_cast<size_t>(side == 1 ? slot : (4 - slot) % 4)];
  return (side << a) | (uv[0] << u) | (uv[1] << v);
}

int quad_slot(Face f, int corner) {
  for (int slot = 0; slot < 4; ++slot)
    if (quad_corner(f, slot) == corner) return slot;
  return -1;
}

std::vector<CornerFan> corner_fans(const LinkedVolume& volume, const Vec3i& g) {
  const CornerCells cells = cells_around(volume, g);
  const PartnerOverrides overrides = edge_overrides(volume, cells);
  return trace_fans(volume, cells, [&](int k, int a, int edge) {
    const OctantFace o = overrides[static_cast<size_t>(k)][static_cast<size_t>(a)][static_cast<size_t>(edge)];
    return o.valid() ? o : material_partner(volume, cells, k, a, edge);
  });
}

}  // namespace cleave
