#pragma once
// Which links a cutting surface severs. A link joins two face-adjacent cells; its dual segment
// runs between the two cell centres. A link is cut when that segment crosses the cutting surface.
//
//   std::vector<Triangle> wall = ...;                      // the cutting surface, triangulated (mm)
//   std::vector<CellFace> links = links_crossing_triangles(volume, wall);
//   volume.cut_links(links);
//
// Each link appears once, as (cell, positive face 1/3/5), in ascending cell order. Links that are
// already cut are left out. Touching counts as crossing (a segment through a triangle's edge or
// an end point on its plane), so two triangles sharing an edge leave no gap.
#include <Eigen/Geometry>
#include <array>
#include <span>
#include <vector>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

using Triangle = std::array<Vec3, 3>;

/// True when segment [a, b] meets triangle t (inclusive of edges and the segment's end points).
bool segment_crosses_triangle(const Vec3& a, const Vec3& b, const Triangle& t);

/// Uncut links whose dual segments cross any of `triangles`.
std::vector<CellFace> links_crossing_triangles(const LinkedVolume& volume, std::span<const Triangle> triangles);

/// Uncut links between a cell for which `in_a(c)` holds and a neighbour for which it does not,
/// restricted to pairs for which `keep(cell_in_a, neighbour)` holds.
template <typename InA, typename Keep>
std::vector<CellFace> links_leaving(const LinkedVolume& volume, std::span<const CellId> cells, InA&& in_a, Keep&& keep) {
  std::vector<CellFace> out;
  for (const CellId c : cells)
    for (Face f = 0; f < kFaceCount; ++f) {
      const CellId n = volume.neighbor(c, f);
      if (n == kNone || volume.is_cut(c, f) || in_a(n) || !keep(c, n)) continue;
      out.push_back({c, f});
    }
  return out;
}

}  // namespace cleave
