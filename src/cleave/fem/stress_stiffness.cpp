#include "cleave/fem/stress_stiffness.hpp"

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/fem/corotation.hpp"

namespace cleave {

Vec6 tensile_part(const Vec6& stress_kPa) {
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(from_voigt(stress_kPa));
  const Vec3 values = eigen.eigenvalues();
  if (values.minCoeff() >= 0) return stress_kPa;
  if (values.maxCoeff() <= 0) return Vec6::Zero();
  const Mat3& axes = eigen.eigenvectors();
  return to_voigt(axes * values.cwiseMax(0.0).asDiagonal() * axes.transpose());
}

void corotated_cell_tension(const LinkedVolume& volume, const ElementTable& table, std::span<const Vec6> residual_stress_kPa,
                            const Vector& displacement_mm, const std::vector<Mat3>& rotations, std::vector<Vec6>& tension_kPa) {
  tension_kPa.resize(static_cast<std::size_t>(volume.cell_count()));
  const double h = table.cell_size_mm;
  tbb::parallel_for(tbb::blocked_range<CellId>(0, volume.cell_count()), [&](const tbb::blocked_range<CellId>& r) {
    for (CellId c = r.begin(); c != r.end(); ++c) {
      const auto ci = static_cast<std::size_t>(c);
      const Mat3 f = hex8_center_deformation_gradient(cell_displacement(volume, c, displacement_mm), h);
      const Mat3 stretch = rotations[ci].transpose() * f;
      Vec6 strain = to_voigt(0.5 * (stretch + stretch.transpose()) - Mat3::Identity());
      strain.tail<3>() *= 2.0;  // engineering shear
      Vec6 stress = table.of_label(volume.cell_label(c)).elasticity_kPa * strain;
      if (!residual_stress_kPa.empty()) stress += residual_stress_kPa[ci];
      tension_kPa[ci] = tensile_part(stress);
    }
  });
}

}  // namespace cleave
