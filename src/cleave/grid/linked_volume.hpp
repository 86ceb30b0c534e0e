#pragma once
// The linked volume (paper section 6, after Dick, Georgii & Westermann 2011): the active
// hexahedral cells of a uniform grid, the links between face-adjacent cells (each with a cut
// flag), and the simulation vertices. A grid corner is one vertex only while the cells around
// it are connected through uncut links around that corner; cutting links splits it into one
// vertex per connected group. This class is the single owner of topology: every operator
// (stiffness, mass, T, Laplacian, surface) reads cells, links and vertices from here, so a cut
// is one change seen by all.
//
// Conventions
//   Faces:   0 = -x, 1 = +x, 2 = -y, 3 = +y, 4 = -z, 5 = +z; opposite(f) = f ^ 1.
//   Corners: index bit 0 = +x, bit 1 = +y, bit 2 = +z, i.e. corner c of a cell at voxel v lies at
//            grid corner v + (c & 1, (c >> 1) & 1, (c >> 2) & 1). This is also the hex8 node order.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "cleave/grid/grid_spec.hpp"
#include "cleave/grid/label_volume.hpp"

namespace cleave {

using Face = int;  ///< 0..5, see the header comment
inline constexpr int kFaceCount = 6;
inline constexpr int kCornerCount = 8;
inline constexpr Face opposite(Face f) { return f ^ 1; }
/// Unit step in voxel coordinates across face f.
Vec3i face_step(Face f);
/// Offset (0/1 per axis) of corner c from the cell's voxel coordinates.
inline Vec3i corner_offset(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }
/// Trilinear weight of corner c at local coordinates t (each in [0, 1]) of a cell.
inline double trilinear_corner_weight(int c, const Vec3& t) {
  const Vec3i o = corner_offset(c);
  return (o.x() ? t.x() : 1 - t.x()) * (o.y() ? t.y() : 1 - t.y()) * (o.z() ? t.z() : 1 - t.z());
}
/// The 4 corners (cell-local indices) lying on face f.
std::array<int, 4> face_corners(Face f);

/// One face link seen from one of its two cells.
struct CellFace {
  CellId cell = kNone;
  Face face = 0;
};

/// A grid corner's vertex that a cut divided: `original` keeps serving one group of cells and
/// `created` are the new vertices of the other groups (each starts at the original's position).
struct VertexSplit {
  VertexId original = kNone;
  std::vector<VertexId> created;
};

/// What a cut changed, so that operators and surfaces update only what is affected.
struct CutReport {
  int links_cut = 0;                  ///< links that were uncut before and are cut now
  std::vector<VertexSplit> splits;    ///< vertices that were divided
  std::vector<CellId> touched_cells;  ///< cells that lost a link or whose corner vertices changed
};

class LinkedVolume {
 public:
  LinkedVolume() = default;
  /// Builds cells for every voxel with a non-zero label, links between all face-adjacent
  /// cells (all uncut), and one vertex per grid corner touched by a cell.
  /// Throws InputError when the volume has no inside voxel.
  static LinkedVolume from_labels(const LabelVolume& volume);

  const GridSpec& grid() const { return grid_; }
  CellId cell_count() const { return static_cast<CellId>(voxel_.size()); }
  VertexId vertex_count() const { return static_cast<VertexId>(vertex_corner_.size()); }

  // Cells ------------------------------------------------------------------------------------
  const Vec3i& cell_voxel(CellId c) const { return voxel_[static_cast<size_t>(c)]; }
  Label cell_label(CellId c) const { return label_[static_cast<size_t>(c)]; }
  Vec3 cell_center_mm(CellId c) const { return grid_.voxel_center_mm(cell_voxel(c)); }
  /// Cell at voxel v, or kNone when v is outside the grid or outside the body.
  CellId cell_at_voxel(const Vec3i& v) const;
  /// Cell containing point p (mm), or kNone.
  CellId cell_containing(const Vec3& p_mm) const { return cell_at_voxel(grid_.voxel_of(p_mm)); }

  // Links ------------------------------------------------------------------------------------
  /// The face-adjacent cell across face f, whether or not the link is cut; kNone at the body's boundary.
  CellId neighbor(CellId c, Face f) const { return neighbor_[static_cast<size_t>(c)][static_cast<size_t>(f)]; }
  bool is_cut(CellId c, Face f) const { return (cut_mask_[static_cast<size_t>(c)] >> f) & 1u; }
  /// True when the neighbour across f exists and the link is not cut (the cells share that face).
  bool linked(CellId c, Face f) const { return neighbor(c, f) != kNone && !is_cut(c, f); }
  /// Number of uncut links (each counted once).
  std::int64_t link_count() const;
  /// Number of links that were cut (each counted once).
  std::int64_t cut_link_count() const;

  // Vertices ---------------------------------------------------------------------------------
  /// Vertex at corner `corner` (0..7) of cell c.
  VertexId corner_vertex(CellId c, int corner) const {
    return corner_vertex_[static_cast<size_t>(c)][static_cast<size_t>(corner)];
  }
  const std::array<VertexId, 8>& cell_vertices(CellId c) const { return corner_vertex_[static_cast<size_t>(c)]; }
  /// Grid corner a vertex sits at (split vertices share their grid corner).
  const Vec3i& vertex_grid_corner(VertexId v) const { return vertex_corner_[static_cast<size_t>(v)]; }
  /// Reference (undeformed) position of a vertex.
  Vec3 vertex_position_mm(VertexId v) const { return grid_.corner_position_mm(vertex_grid_corner(v)); }
  /// For each vertex, the cells using it (rebuilt on demand after a cut).
  const std::vector<std::vector<CellId>>& vertex_cells() const;

  // Cutting ----------------------------------------------------------------------------------
  /// Marks links as cut (both sides), splits the vertices around them whose cells are no longer
  /// connected around the corner, and reports what changed. Work is proportional to the number
  /// of links given, not to the model size. Links already cut and faces without a neighbour are
  /// ignored. Vertex ids of unaffected vertices never change; new vertices are appended.
  CutReport cut_links(std::span<const CellFace> links);

  // Connected components -----------------------------------------------------------------------
  /// Component id per cell (0..component_count()-1), connected through uncut links.
  const std::vector<int>& cell_components() const;
  int component_count() const;

  /// Bytes held by this structure (cells, links, vertices, lookup tables).
  std::size_t bytes() const;

 private:
  /// Regroups the cells around grid corner g by their uncut links; keeps existing vertex ids for
  /// the first group of each old vertex and creates new ones for the others.
  void regroup_corner(const Vec3i& g, CutReport& report);

  GridSpec grid_;
  std::vector<CellId> voxel_to_cell_;                 ///< per voxel: cell id or kNone
  std::vector<Vec3i> voxel_;                          ///< per cell
  std::vector<Label> label_;                          ///< per cell
  std::vector<std::array<CellId, 6>> neighbor_;       ///< per cell and face
  std::vector<std::uint8_t> cut_mask_;                ///< per cell: bit f set = link across f cut
  std::vector<std::array<VertexId, 8>> corner_vertex_;  ///< per cell and corner
  std::vector<Vec3i> vertex_corner_;                  ///< per vertex: its grid corner

  mutable std::vector<std::vector<CellId>> vertex_cells_;
  mutable bool vertex_cells_valid_ = false;
  mutable std::vector<int> components_;
  mutable int component_count_ = 0;
  mutable bool components_valid_ = false;
};

}  // namespace cleave
