#include "paper_reference_directions.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/solve/plain_conjugate_gradient.hpp"
#include "cleave/stress/cell_laplacian.hpp"
#include "cleave/stress/stroke_constraints.hpp"

namespace cleave::bench {
namespace {

using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// The same Tikhonov guard as stress/line_field_interpolation.cpp (relative to w_L).
constexpr double kGuard = 1e-10;

/// The paper's plain CG (one thread, no preconditioner) from x; returns its iterations.
int plain_conjugate_gradients(const RowMatrix& a, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  const PlainCgOutcome cg = plain_conjugate_gradient(a, b, x, kPaperCgRelativeTolerance, kPaperCgMaxIterations);
  if (cg.relative_residual > kPaperCgRelativeTolerance)
    throw ComputeError(fmt::format("paper CG for the direction fields did not converge: relative residual {:.3g} after {} iterations",
                                   cg.relative_residual, cg.iterations));
  return cg.iterations;
}

/// Solves the 6 component systems of one line field; returns the tensors and adds the iterations.
std::vector<Mat3> interpolate_line_field(const RowMatrix& smoothness, const std::vector<LineTarget>& targets,
                                         double constraint_weight, Eigen::MatrixXd& guess, int& iterations) {
  const Eigen::Index n = smoothness.rows();
  RowMatrix system = smoothness;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 6);
  for (const LineTarget& t : targets) {
    system.coeffRef(t.cell, t.cell) += constraint_weight;
    rhs.row(t.cell) += constraint_weight * to_voigt(t.tensor).transpose();
  }
  if (guess.rows() != n) guess = Eigen::MatrixXd::Zero(n, 6);
  for (int k = 0; k < 6; ++k) {
    Eigen::VectorXd x = guess.col(k);
    iterations += plain_conjugate_gradients(system, rhs.col(k), x);
    guess.col(k) = x;
  }
  std::vector<Mat3> field(static_cast<std::size_t>(n));
  for (Eigen::Index c = 0; c < n; ++c) field[static_cast<std::size_t>(c)] = from_voigt(guess.row(c).transpose());
  return field;
}

}  // namespace

PaperDirections::PaperDirections(const TissueModel& model, const StressDesign& design) : model_(model), design_(design) {
  const RowMatrix l = cell_laplacian(model.volume);
  smoothness_ = design.weights.laplacian * RowMatrix(RowMatrix(l.transpose()) * l);
  for (CellId c = 0; c < model.volume.cell_count(); ++c) smoothness_.coeffRef(c, c) += kGuard * design.weights.laplacian;
  smoothness_.makeCompressed();
}

PaperDirectionResult PaperDirections::interpolate(const std::vector<DesignStroke>& strokes) {
  const double tolerance_mm = design_.snap_tolerance_cells * model_.volume.grid().cell_size_mm;
  PaperDirectionResult result;
  const std::vector<Mat3> langer = interpolate_line_field(smoothness_, stroke_line_targets(model_, strokes, tolerance_mm),
                                                          design_.weights.constraint, langer_guess_, result.iterations);
  const std::vector<Mat3> normal = interpolate_line_field(smoothness_, surface_normal_targets(model_),
                                                          design_.weights.constraint, normal_guess_, result.iterations);
  result.frames = direction_frames(langer, normal);
  return result;
}

Eigen::VectorXd frame_line_tensors(const std::vector<DirectionFrame>& frames) {
  Eigen::VectorXd out(12 * static_cast<Eigen::Index>(frames.size()));
  for (std::size_t c = 0; c < frames.size(); ++c) {
    const auto i = 12 * static_cast<Eigen::Index>(c);
    out.segment<6>(i) = to_voigt(frames[c].langer * frames[c].langer.transpose());
    out.segment<6>(i + 6) = to_voigt(frames[c].normal * frames[c].normal.transpose());
  }
  return out;
}

}  // namespace cleave::bench
