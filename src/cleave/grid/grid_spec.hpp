#pragma once
// A uniform Cartesian grid of cubic cells: where it lies and how fine it is.
#include <cmath>
#include <cstdint>

#include "cleave/core/types.hpp"

namespace cleave {

/// Cells are cubes of edge `cell_size_mm`; voxel (i, j, k) spans
/// [origin + (i, j, k) h, origin + (i+1, j+1, k+1) h]. Grid corners run 0..dims (inclusive).
struct GridSpec {
  Vec3i dims{0, 0, 0};          ///< number of cells along x, y, z
  Vec3 origin_mm{0, 0, 0};      ///< position of grid corner (0, 0, 0)
  double cell_size_mm = 1.0;    ///< edge length h of every cell

  std::int64_t voxel_count() const { return std::int64_t{dims.x()} * dims.y() * dims.z(); }
  std::int64_t corner_count() const { return std::int64_t{dims.x() + 1} * (dims.y() + 1) * (dims.z() + 1); }
  bool contains_voxel(const Vec3i& v) const {
    return v.x() >= 0 && v.y() >= 0 && v.z() >= 0 && v.x() < dims.x() && v.y() < dims.y() && v.z() < dims.z();
  }
  std::int64_t voxel_index(const Vec3i& v) const {
    return (std::int64_t{v.z()} * dims.y() + v.y()) * dims.x() + v.x();
  }
  std::int64_t corner_index(const Vec3i& c) const {
    return (std::int64_t{c.z()} * (dims.y() + 1) + c.y()) * (dims.x() + 1) + c.x();
  }
  Vec3 corner_position_mm(const Vec3i& c) const { return origin_mm + cell_size_mm * c.cast<double>(); }
  Vec3 voxel_center_mm(const Vec3i& v) const {
    return origin_mm + cell_size_mm * (v.cast<double>() + Vec3::Constant(0.5));
  }
  /// Voxel containing point p (may lie outside the grid; check with contains_voxel).
  Vec3i voxel_of(const Vec3& p_mm) const {
    const Vec3 g = (p_mm - origin_mm) / cell_size_mm;
    return {static_cast<int>(std::floor(g.x())), static_cast<int>(std::floor(g.y())), static_cast<int>(std::floor(g.z()))};
  }
  Vec3 extent_mm() const { return cell_size_mm * dims.cast<double>(); }
};

}  // namespace cleave
