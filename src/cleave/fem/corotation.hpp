#pragma once
// Corotational frames of the cells: the rotation R of each cell from the deformation gradient F
// at its centre, by polar decomposition F = R S (R proper orthogonal, S symmetric).
#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include "cleave/fem/hex8_element.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

/// The rotation of F = R S: the proper rotation nearest to F (det R = +1 also for an inverted F,
/// where the axis of the smallest singular value is flipped). Identity for F = I. For det F > 0 by
/// the scaled Newton iteration X <- (g X + X^-T / g) / 2 (Higham; g the Frobenius scaling), which
/// converges quadratically to the polar factor in about 4 iterations for tissue strains (2.6x
/// faster than the SVD); the SVD otherwise, and where Newton does not settle.
Mat3 rotation_from_deformation_gradient(const Mat3& deformation_gradient);
/// rotation_from_deformation_gradient of each of `gradients` into `rotations` (as many), eight at
/// a time in AVX-512 lanes where the CPU has them (fem/polar_avx512.hpp), else four in AVX2 lanes
/// (the same Newton iteration, each lane stopping where it settles; lanes that go to the SVD are
/// taken one by one): the same rotations to rounding, about 3x faster than one at a time with 4
/// lanes (the cell passes of every dynamic step run it on all cells).
void rotations_from_deformation_gradients(std::span<const Mat3> gradients, std::span<Mat3> rotations);
/// How many gradients the AVX2 lanes take at once (one register of doubles).
inline constexpr int kPolarLanes = 4;
/// How many gradients the cell passes hand to rotations_from_deformation_gradients at once (the
/// AVX-512 lanes, or two groups of AVX2 lanes).
inline constexpr int kPolarBatch = 8;
/// The same by the SVD alone (the reference the Newton iteration is tested against). A gradient
/// with a non-finite entry has no rotation: all NaN, from either function (the step that made it
/// then reports its non-finite displacement).
Mat3 rotation_by_svd(const Mat3& deformation_gradient);

/// The strain of F = R S in the frame turned by R: sym(R^T F) - I, as Voigt with engineering
/// shear (what D multiplies).
Vec6 corotated_strain(const Mat3& deformation_gradient, const Mat3& rotation);

/// R per cell for vertex displacements `u` (3 n_v, mm); computed in parallel.
void cell_rotations(const LinkedVolume& volume, const Vector& displacement_mm, std::vector<Mat3>& rotations);

/// The 24 nodal displacements of cell c gathered from `u` (3 n_v).
Vec24 cell_displacement(const LinkedVolume& volume, CellId c, const Vector& displacement_mm);

/// Corotated element displacement R^T x_e - X_e (24, mm) of a cell with rotation R: the nodal
/// positions x = X + u brought back into the cell's reference frame, relative to node 0 (K^e and
/// T^e do not see translations).
Vec24 corotated_displacement(const Vec24& cell_displacement_mm, const Mat3& rotation, double h_mm);

/// For the cells [begin, end) (one parallel task's range): F at each cell's centre and its
/// rotation into rotations[c], four cells at a time (rotations_from_deformation_gradients), then
/// each(c, F) per cell. `rotations` holds one per cell of the volume.
template <typename Each>
void cell_frames_in_range(const LinkedVolume& volume, const Vector& displacement_mm, CellId begin, CellId end,
                          std::vector<Mat3>& rotations, Each&& each) {
  constexpr CellId kBatch = kPolarBatch;
  const double h = volume.grid().cell_size_mm;
  std::array<Mat3, kBatch> gradients;
  for (CellId first = begin; first < end; first += kBatch) {
    const auto count = static_cast<std::size_t>(std::min(kBatch, end - first));
    for (std::size_t i = 0; i < count; ++i)
      gradients[i] = hex8_center_deformation_gradient(cell_displacement(volume, first + static_cast<CellId>(i), displacement_mm), h);
    rotations_from_deformation_gradients(std::span<const Mat3>(gradients.data(), count),
                                         std::span<Mat3>(rotations).subspan(static_cast<std::size_t>(first), count));
    for (std::size_t i = 0; i < count; ++i) each(first + static_cast<CellId>(i), gradients[i]);
  }
}

}  // namespace cleave
