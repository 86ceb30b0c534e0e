#include "cleave/stress/line_field_interpolation.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/stress/cell_laplacian.hpp"

namespace cleave {
LineFieldInterpolator::LineFieldInterpolator(const LinkedVolume& volume, const DesignWeights& weights)
    : volume_(volume), weights_(weights), cell_count_(volume.cell_count()) {
  const Eigen::SparseMatrix<double> l = cell_laplacian(volume);
  Eigen::SparseMatrix<double> ltl = Eigen::SparseMatrix<double>(l.transpose()) * l;
  smoothness_ = weights.laplacian * ltl;
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
  std::vector<CellId> constrained;
  for (const LineTarget& t : targets) constrained.push_back(t.cell);
  const std::vector<bool> pinned = cells_of_unconstrained_pieces(volume_, constrained);
  for (CellId c = 0; c < cell_count_; ++c)
    if (pinned[static_cast<std::size_t>(c)]) system.coeffRef(c, c) += weights_.laplacian;  // piece without targets -> 0
  system.makeCompressed();
  Eigen::MatrixXd x = previous_;
  try {
    if (!cholesky_.solve_with_current_factor(system, rhs, x, kReuseTolerance, kMaxReuseIterations)) {
      cholesky_.factorize(system);
      ++factorizations_;
      x = cholesky_.solve_refined(system, rhs);
    }
  } catch (const ComputeError& e) {
    throw ComputeError(fmt::format("line field interpolation: {}", e.what()));
  }
  for (CellId c = 0; c < cell_count_; ++c)
    if (!x.row(c).allFinite())
      throw ComputeError(fmt::format("line field interpolation: the tensor of cell {} is not finite; expected finite "
                                     "direction targets",
                                     c));
  previous_ = x;
  std::vector<Mat3> field(static_cast<std::size_t>(cell_count_));
  for (CellId c = 0; c < cell_count_; ++c) field[static_cast<std::size_t>(c)] = from_voigt(x.row(c).transpose());
  return field;
}

}  // namespace cleave
