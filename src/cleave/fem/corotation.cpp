#include "cleave/fem/corotation.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/fem/hex8_element.hpp"

namespace cleave {

Mat3 rotation_from_deformation_gradient(const Mat3& f) {
  const Eigen::JacobiSVD<Mat3> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 u = svd.matrixU();
  const Mat3 v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0) u.col(2) *= -1.0;  // singular values are sorted: flip the smallest
  return u * v.transpose();
}

Vec24 cell_displacement(const LinkedVolume& volume, CellId c, const Vector& u) {
  Vec24 ue;
  const auto& corners = volume.cell_vertices(c);
  for (int a = 0; a < kCornerCount; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * corners[static_cast<std::size_t>(a)]);
  return ue;
}

void cell_rotations(const LinkedVolume& volume, const Vector& u, std::vector<Mat3>& rotations) {
  rotations.resize(static_cast<std::size_t>(volume.cell_count()));
  const double h = volume.grid().cell_size_mm;
  tbb::parallel_for(tbb::blocked_range<CellId>(0, volume.cell_count()), [&](const tbb::blocked_range<CellId>& r) {
    for (CellId c = r.begin(); c != r.end(); ++c)
      rotations[static_cast<std::size_t>(c)] =
          rotation_from_deformation_gradient(hex8_center_deformation_gradient(cell_displacement(volume, c, u), h));
  });
}

Vec24 corotated_displacement(const Vec24& ue, const Mat3& r, double h_mm) {
  Vec24 out;
  const Vec3 u0 = ue.segment<3>(0);
  for (int a = 0; a < kCornerCount; ++a) {
    const Vec3 offset = h_mm * corner_offset(a).cast<double>();
    out.segment<3>(3 * a) = r.transpose() * (offset + ue.segment<3>(3 * a) - u0) - offset;
  }
  return out;
}

}  // namespace cleave
