#include "cleave/fem/corotation.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <Eigen/SVD>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/fem/hex8_element.hpp"

namespace cleave {

namespace {

/// Newton steps after which an iteration that has not settled goes to the SVD (quadratic
/// convergence needs 3-6 for stretches up to 1:100; the scaling brings far ones in fast).
constexpr int kNewtonMaxIterations = 16;
/// Settled: no entry of X moved by more than this in the last step. The step's change is the
/// error it started from, and Newton leaves about half its square (quadratic convergence): below
/// 1e-15 here. (It was 1e-13, which took one step more for the same rotation to rounding.)
constexpr double kNewtonSettled = 3e-8;

}  // namespace

Mat3 rotation_from_deformation_gradient(const Mat3& f) {
  Mat3 x = f;
  for (int k = 0; k < kNewtonMaxIterations; ++k) {
    const double det = x.determinant();
    if (!(det > 0) || !std::isfinite(det)) break;  // inverted, flat or not finite: the SVD decides
    Mat3 cofactor;  // X^-T = cofactor / det
    cofactor.col(0) = x.col(1).cross(x.col(2));
    cofactor.col(1) = x.col(2).cross(x.col(0));
    cofactor.col(2) = x.col(0).cross(x.col(1));
    const double g = std::sqrt(std::sqrt(cofactor.squaredNorm() / x.squaredNorm()) / det);
    const Mat3 next = 0.5 * (g * x + cofactor / (g * det));
    const double change = (next - x).cwiseAbs().maxCoeff();
    x = next;
    if (change < kNewtonSettled) return x;
  }
  return rotation_by_svd(f);
}

Mat3 rotation_by_svd(const Mat3& f) {
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

Vec6 corotated_strain(const Mat3& f, const Mat3& r) {
  const Mat3 stretch = r.transpose() * f;
  Vec6 strain = to_voigt(0.5 * (stretch + stretch.transpose()) - Mat3::Identity());
  strain.tail<3>() *= 2.0;  // engineering shear
  return strain;
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
