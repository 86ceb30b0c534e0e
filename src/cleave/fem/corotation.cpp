#include "cleave/fem/corotation.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotated_cells_avx512.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/fem/polar_avx512.hpp"

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

namespace {

constexpr int kLanes = kPolarLanes;
using Lanes = Eigen::Array<double, kLanes, 1>;

/// `count` (1 to kLanes) gradients' Newton iteration in lanes: entry (i, j) of every lane's X in
/// x[3 i + j]. A lane whose determinant is not positive and finite, or that has not settled after
/// kNewtonMaxIterations, goes to the SVD, as in rotation_from_deformation_gradient.
void rotations_in_lanes(const Mat3* f, Mat3* rotations, int count) {
  std::array<Lanes, 9> x;
  for (int lane = 0; lane < kLanes; ++lane) {
    const Mat3& source = f[lane < count ? lane : 0];  // spare lanes repeat the first
    for (int e = 0; e < 9; ++e) x[static_cast<std::size_t>(e)][lane] = source(e / 3, e % 3);
  }
  const auto at = [&](int i, int j) -> const Lanes& { return x[static_cast<std::size_t>(3 * i + j)]; };
  Eigen::Array<bool, kLanes, 1> settled = Eigen::Array<bool, kLanes, 1>::Constant(false);
  Eigen::Array<bool, kLanes, 1> to_svd = Eigen::Array<bool, kLanes, 1>::Constant(false);
  for (int lane = count; lane < kLanes; ++lane) settled[lane] = true;
  for (int k = 0; k < kNewtonMaxIterations && !(settled || to_svd).all(); ++k) {
    // X^-T = cofactor / det, the cofactor's columns the cross products of X's columns.
    std::array<Lanes, 9> cofactor;
    const auto cross_into = [&](int column, int p, int q) {
      cofactor[static_cast<std::size_t>(0 + column)] = at(1, p) * at(2, q) - at(2, p) * at(1, q);
      cofactor[static_cast<std::size_t>(3 + column)] = at(2, p) * at(0, q) - at(0, p) * at(2, q);
      cofactor[static_cast<std::size_t>(6 + column)] = at(0, p) * at(1, q) - at(1, p) * at(0, q);
    };
    cross_into(0, 1, 2);
    cross_into(1, 2, 0);
    cross_into(2, 0, 1);
    const Lanes det = at(0, 0) * cofactor[0] + at(1, 0) * cofactor[3] + at(2, 0) * cofactor[6];
    Lanes cofactor_norm = Lanes::Zero();
    Lanes x_norm = Lanes::Zero();
    for (std::size_t e = 0; e < 9; ++e) {
      cofactor_norm += cofactor[e].square();
      x_norm += x[e].square();
    }
    // Inverted, flat or not finite: the SVD decides (as rotation_from_deformation_gradient).
    to_svd = to_svd || (!settled && !(det > 0 && det.isFinite()));
    const Eigen::Array<bool, kLanes, 1> moving = !(settled || to_svd);
    const Lanes safe_det = moving.select(det, Lanes::Ones());
    const Lanes g = ((cofactor_norm / moving.select(x_norm, Lanes::Ones())).sqrt() / safe_det).sqrt();
    const Lanes cofactor_scale = 0.5 / (g * safe_det);
    const Lanes x_scale = 0.5 * g;
    Lanes change = Lanes::Zero();
    for (std::size_t e = 0; e < 9; ++e) {
      const Lanes next = x_scale * x[e] + cofactor_scale * cofactor[e];
      change = change.max((next - x[e]).abs());
      x[e] = moving.select(next, x[e]);
    }
    settled = settled || (moving && change < kNewtonSettled);
  }
  for (int lane = 0; lane < count; ++lane) {
    if (!settled[lane]) {
      rotations[lane] = rotation_by_svd(f[lane]);
      continue;
    }
    for (int e = 0; e < 9; ++e) rotations[lane](e / 3, e % 3) = x[static_cast<std::size_t>(e)][lane];
  }
}

}  // namespace

void rotations_from_deformation_gradients(std::span<const Mat3> gradients, std::span<Mat3> rotations) {
  if (gradients.size() != rotations.size())
    throw InputError(fmt::format("polar decomposition: {} deformation gradients but room for {} rotations", gradients.size(),
                                 rotations.size()));
  static_assert(sizeof(Mat3) == 9 * sizeof(double));
  if (avx512_cell_pass_supported()) {
    const PolarIteration iteration{kNewtonMaxIterations, kNewtonSettled};
    for (std::size_t i = 0; i < gradients.size(); i += 8) {
      const int count = static_cast<int>(std::min<std::size_t>(8, gradients.size() - i));
      const unsigned settled = polar_rotations_avx512(gradients[i].data(), rotations[i].data(), count, iteration);
      for (int lane = 0; lane < count; ++lane)
        if (((settled >> lane) & 1u) == 0) rotations[i + static_cast<std::size_t>(lane)] = rotation_by_svd(gradients[i + static_cast<std::size_t>(lane)]);
    }
    return;
  }
  for (std::size_t i = 0; i < gradients.size(); i += kLanes) {
    const int count = static_cast<int>(std::min<std::size_t>(kLanes, gradients.size() - i));
    rotations_in_lanes(gradients.data() + i, rotations.data() + i, count);
  }
}

Mat3 rotation_by_svd(const Mat3& f) {
  // Eigen's SVD of a non-finite matrix leaves parts of U and V unset (uninitialized memory).
  if (!f.allFinite()) return Mat3::Constant(std::numeric_limits<double>::quiet_NaN());
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
  tbb::parallel_for(tbb::blocked_range<CellId>(0, volume.cell_count()), [&](const tbb::blocked_range<CellId>& r) {
    cell_frames_in_range(volume, u, r.begin(), r.end(), rotations, [](CellId, const Mat3&) {});
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
