#include "cleave/viz/displacement_at_point.hpp"

#include <limits>

namespace cleave {
namespace {

constexpr int kSearchRadiusCells = 2;

}  // namespace

CellId nearest_accepted_cell(const LinkedVolume& volume, const Vec3& p_mm, const std::function<bool(CellId)>& accept) {
  const Vec3i v = volume.grid().voxel_of(p_mm);
  CellId best = kNone;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int dz = -kSearchRadiusCells; dz <= kSearchRadiusCells; ++dz)
    for (int dy = -kSearchRadiusCells; dy <= kSearchRadiusCells; ++dy)
      for (int dx = -kSearchRadiusCells; dx <= kSearchRadiusCells; ++dx) {
        const CellId c = volume.cell_at_voxel(v + Vec3i(dx, dy, dz));
        if (c == kNone) continue;
        // Distance first: the caller's test runs only for a cell that would be nearer.
        const double d2 = (volume.cell_center_mm(c) - p_mm).squaredNorm();
        if (d2 >= best_d2 || !accept(c)) continue;
        best_d2 = d2;
        best = c;
      }
  return best;
}

std::optional<CellPoint> locate_in_accepted_cell(const LinkedVolume& volume, const Vec3& p_mm,
                                                 const std::function<bool(CellId)>& accept) {
  const CellId c = nearest_accepted_cell(volume, p_mm, accept);
  if (c == kNone) return std::nullopt;
  const GridSpec& grid = volume.grid();
  const Vec3 t = ((p_mm - grid.corner_position_mm(volume.cell_voxel(c))) / grid.cell_size_mm)
                     .cwiseMax(Vec3::Zero())
                     .cwiseMin(Vec3::Ones());
  CellPoint at;
  at.cell = c;
  for (int k = 0; k < kCornerCount; ++k) at.weights[static_cast<std::size_t>(k)] = trilinear_corner_weight(k, t);
  return at;
}

Vec3 displacement_at(const LinkedVolume& volume, std::span<const Vec3> displacement_mm, const CellPoint& at) {
  Vec3 u = Vec3::Zero();
  for (int k = 0; k < kCornerCount; ++k)
    u += at.weights[static_cast<std::size_t>(k)] * displacement_mm[static_cast<std::size_t>(volume.corner_vertex(at.cell, k))];
  return u;
}

std::optional<Vec3> displacement_at_point(const LinkedVolume& volume, std::span<const Vec3> displacement_mm,
                                          const Vec3& p_mm, const std::function<bool(CellId)>& accept) {
  const std::optional<CellPoint> at = locate_in_accepted_cell(volume, p_mm, accept);
  if (!at) return std::nullopt;
  return displacement_at(volume, displacement_mm, *at);
}

}  // namespace cleave
