#include "cleave/fem/stress_stiffness.hpp"

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/fem/corotation.hpp"

namespace cleave {
namespace {

/// All principal minors non-negative (Sylvester's criterion for semi-definiteness).
bool positive_semidefinite(const Vec6& s) {
  return s[0] >= 0 && s[1] >= 0 && s[2] >= 0 && s[0] * s[1] >= s[3] * s[3] && s[0] * s[2] >= s[4] * s[4] &&
         s[1] * s[2] >= s[5] * s[5] && from_voigt(s).determinant() >= 0;
}

}  // namespace

Vec6 tensile_part(const Vec6& stress_kPa) {
  // Most cells of tissue under tension are wholly tensile, the rest often wholly compressive:
  // the eigen decomposition only for the mixed ones.
  if (positive_semidefinite(stress_kPa)) return stress_kPa;
  if (positive_semidefinite(-stress_kPa)) return Vec6::Zero();
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(from_voigt(stress_kPa));
  const Mat3& axes = eigen.eigenvectors();
  return to_voigt(axes * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() * axes.transpose());
}

void cell_rotations_and_tension(const LinkedVolume& volume, const ElementTable& table, std::span<const Vec6> residual_stress_kPa,
                                const Vector& displacement_mm, std::vector<Mat3>& rotations, std::vector<Vec6>& tension_kPa) {
  const auto cells = static_cast<std::size_t>(volume.cell_count());
  rotations.resize(cells);
  tension_kPa.resize(cells);
  tbb::parallel_for(tbb::blocked_range<CellId>(0, volume.cell_count()), [&](const tbb::blocked_range<CellId>& r) {
    cell_frames_in_range(volume, displacement_mm, r.begin(), r.end(), rotations, [&](CellId c, const Mat3& f) {
      const auto ci = static_cast<std::size_t>(c);
      Vec6 stress = table.of_label(volume.cell_label(c)).elasticity_kPa * corotated_strain(f, rotations[ci]);
      if (!residual_stress_kPa.empty()) stress += residual_stress_kPa[ci];
      tension_kPa[ci] = tensile_part(stress);
    });
  });
}

}  // namespace cleave
