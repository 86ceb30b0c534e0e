#include "cleave/stress/line_field_interpolation.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/stress/cell_laplacian.hpp"

namespace cleave {
namespace {

/// Tikhonov guard relative to the Laplacian weight (dimensionless): keeps pieces without targets
/// well posed (their field becomes 0) and moves constrained fields by ~1e-10 relative.
constexpr double kGuard = 1e-10;

}  // namespace

LineFieldInterpolator::LineFieldInterpolator(const LinkedVolume& volume, const DesignWeights& weights)
    : weights_(weights), cell_count_(volume.cell_count()) {
  const Eigen::SparseMatrix<double> l = cell_laplacian(volume);
  Eigen::SparseMatrix<double> ltl = Eigen::SparseMatrix<double>(l.transpose()) * l;
  smoothness_ = weights.laplacian * ltl;
  for (CellId c = 0; c < cell_count_; ++c) smoothness_.coeffRef(c, c) += kGuard * weights.laplacian;
  smoothness_.makeCompressed();
}

std::vector<Mat3> LineFieldInterpolator::interpolate(const std::vector<LineTarget>& targets) {
  Eigen::SparseMatrix<double> system = smoothness_;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(cell_count_, 6);
  for (const LineTarget& t : targets) {
    if (t.cell < 0 || t.cell >= cell_count_)
      throw InputError(fmt::format("direction target names cell {}; expected 0 to {}", t.cell, cell_count_ - 1));
    system.coeffRef(t.cell, t.cell) += weights_.constraint;
    rhs.row(t.cell) += weights_.constraint * to_voigt(t.tensor).transpose();
  }
  cholesky_.factorize(system);
  const Eigen::MatrixXd x = cholesky_.solve(rhs);
  std::vector<Mat3> field(static_cast<std::size_t>(cell_count_));
  for (CellId c = 0; c < cell_count_; ++c) field[static_cast<std::size_t>(c)] = from_voigt(x.row(c).transpose());
  return field;
}

}  // namespace cleave
