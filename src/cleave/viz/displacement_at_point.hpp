#pragma once
// Displacement of a material point that lies on a cut: a point on a cut face belongs to two
// pieces at once, so the caller says which side it means by accepting only cells on that side.
// The displacement is the trilinear interpolation of the chosen cell's eight corner vertices,
// with the point's local coordinates clamped to the cell (so a point just outside the chosen
// cell takes the value on its nearest face, i.e. of the split vertices on that side).
//
//   auto body_side = [&](CellId c) { return frame.radial_of(volume.cell_center_mm(c)) > frame.radius_mm; };
//   std::optional<Vec3> u = displacement_at_point(volume, displacement_mm, x_mm, body_side);
//
// Where the same point is read under many displacements (a measurement after every edit), locate
// it once and interpolate each displacement at the located point:
//   std::optional<CellPoint> at = locate_in_accepted_cell(volume, x_mm, body_side);
//   Vec3 u = displacement_at(volume, displacement_mm, *at);
#include <array>
#include <functional>
#include <optional>
#include <span>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

/// The accepted cell whose centre is nearest to p among the 5x5x5 voxels around p, or kNone.
CellId nearest_accepted_cell(const LinkedVolume& volume, const Vec3& p_mm, const std::function<bool(CellId)>& accept);

/// A point located for interpolation: its cell and the trilinear weights of the cell's corners.
struct CellPoint {
  CellId cell = kNone;
  std::array<double, kCornerCount> weights{};
};

/// p in the nearest accepted cell, its local coordinates clamped to the cell; nullopt when no cell
/// around p is accepted.
std::optional<CellPoint> locate_in_accepted_cell(const LinkedVolume& volume, const Vec3& p_mm,
                                                 const std::function<bool(CellId)>& accept);

/// Interpolated displacement (mm) at a located point; `displacement_mm` has one entry per vertex.
Vec3 displacement_at(const LinkedVolume& volume, std::span<const Vec3> displacement_mm, const CellPoint& at);

/// Interpolated displacement (mm) at p in the nearest accepted cell; nullopt when no cell around
/// p is accepted. `displacement_mm` has one entry per vertex.
std::optional<Vec3> displacement_at_point(const LinkedVolume& volume, std::span<const Vec3> displacement_mm,
                                          const Vec3& p_mm, const std::function<bool(CellId)>& accept);

}  // namespace cleave
