// GCC 12 reports -Wnull-dereference inside Eigen (sparse Ref construction, vector dot products)
// after inlining: a false positive for possibly-empty vectors. Silenced for this file's headers.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "cleave/stress/eigenvalue_interpolation.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/solve/plain_conjugate_gradient.hpp"
#include "cleave/stress/cell_laplacian.hpp"
#include "cleave/stress/equilibrium_operator.hpp"

namespace cleave {
namespace {

constexpr double kPaperCgTolerance = 1e-12;    ///< relative residual of the reference CG
constexpr int kPaperCgMaxIterations = 200000;  ///< the plain CG needs many iterations on A^T A

bool same_frames(const std::vector<DirectionFrame>& a, const std::vector<DirectionFrame>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t c = 0; c < a.size(); ++c)
    if (a[c].langer != b[c].langer || a[c].cross != b[c].cross || a[c].normal != b[c].normal) return false;
  return true;
}

}  // namespace

EigenvalueInterpolator::EigenvalueInterpolator(const LinkedVolume& volume, const DesignWeights& weights,
                                               std::vector<VertexId> held_vertices)
    : volume_(volume), weights_(weights), held_vertices_(std::move(held_vertices)) {
  const Eigen::SparseMatrix<double> l = cell_laplacian(volume);
  const Eigen::SparseMatrix<double> ltl = Eigen::SparseMatrix<double>(l.transpose()) * l;
  std::vector<Eigen::Triplet<double>> entries;
  constexpr std::size_t kEntriesPerRow = 26;  // L^T L couples a cell with at most 25 cells; + the guard
  entries.reserve(kEntriesPerRow * 3 * static_cast<std::size_t>(ltl.rows()));
  for (Eigen::Index k = 0; k < ltl.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(ltl, k); it; ++it)
      for (int i = 0; i < 3; ++i)
        entries.emplace_back(static_cast<int>(3 * it.row() + i), static_cast<int>(3 * it.col() + i), weights.laplacian * it.value());
  smoothness_.resize(3 * ltl.rows(), 3 * ltl.cols());
  smoothness_.setFromTriplets(entries.begin(), entries.end());
  scalar_smoothness_ = weights.laplacian * ltl;
  scalar_smoothness_.makeCompressed();
}

EigenvalueSolution EigenvalueInterpolator::solve(const std::vector<DirectionFrame>& frames,
                                                 const std::vector<EigenvalueTarget>& targets, EigenvalueSolver solver,
                                                 const std::vector<Vec3>& warm_start) {
  for (const EigenvalueTarget& t : targets)
    if (t.cell < 0 || t.cell >= volume_.cell_count())
      throw InputError(fmt::format("eigenvalue target names cell {}; expected 0 to {}", t.cell, volume_.cell_count() - 1));
  EigenvalueSolution solution;
  try {
    solution = weights_.equilibrium == 0.0 && solver == EigenvalueSolver::cholesky ? solve_scalar(targets, warm_start)
                                                                                   : solve_coupled(frames, targets, solver, warm_start);
  } catch (const ComputeError& e) {
    throw ComputeError(fmt::format("eigenvalue interpolation: {}", e.what()));
  }
  for (std::size_t c = 0; c < solution.eigenvalues_kPa.size(); ++c)
    if (!solution.eigenvalues_kPa[c].allFinite())
      throw ComputeError(fmt::format("eigenvalue interpolation: the eigenvalues of cell {} are not finite ({}, {}, {} kPa); "
                                     "expected finite stresses (are the control point values and frames finite?)",
                                     c, solution.eigenvalues_kPa[c][0], solution.eigenvalues_kPa[c][1],
                                     solution.eigenvalues_kPa[c][2]));
  return solution;
}

void EigenvalueInterpolator::solve_with_kept_factor(const Eigen::SparseMatrix<double>& system, const Eigen::MatrixXd& rhs,
                                                    Eigen::MatrixXd& x, int& iterations) {
  if (cholesky_.solve_with_current_factor(system, rhs, x, kReuseTolerance, kMaxReuseIterations)) {
    iterations = cholesky_.last_iterations();
    return;
  }
  iterations = cholesky_.last_iterations();
  cholesky_.factorize(system);
  ++factorizations_;
  x = cholesky_.solve_refined(system, rhs);
}

EigenvalueSolution EigenvalueInterpolator::solve_scalar(const std::vector<EigenvalueTarget>& targets,
                                                        const std::vector<Vec3>& warm_start) {
  // Three independent fields: (w_L L^T L + constraints) Lambda = B, Lambda n_c x 3. The matrix
  // depends only on which cells hold control points, the right-hand side on their values.
  const CellId cells = volume_.cell_count();
  std::vector<CellId> constrained;
  for (const EigenvalueTarget& t : targets) constrained.push_back(t.cell);
  const std::vector<bool> pinned = cells_of_unconstrained_pieces(volume_, constrained);
  Eigen::SparseMatrix<double> system = scalar_smoothness_;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(cells, 3);
  for (const EigenvalueTarget& t : targets) {
    system.coeffRef(t.cell, t.cell) += weights_.constraint;
    rhs.row(t.cell) += weights_.constraint * t.eigenvalues_kPa.transpose();
  }
  for (CellId c = 0; c < cells; ++c)
    if (pinned[static_cast<std::size_t>(c)]) system.coeffRef(c, c) += weights_.laplacian;  // no control point -> 0
  system.makeCompressed();
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(cells, 3);
  if (static_cast<Eigen::Index>(warm_start.size()) == cells)
    for (CellId c = 0; c < cells; ++c) x.row(c) = warm_start[static_cast<std::size_t>(c)].transpose();
  EigenvalueSolution solution;
  solve_with_kept_factor(system, rhs, x, solution.iterations);
  solution.eigenvalues_kPa.resize(static_cast<std::size_t>(cells));
  for (CellId c = 0; c < cells; ++c) solution.eigenvalues_kPa[static_cast<std::size_t>(c)] = x.row(c).transpose();
  return solution;
}

EigenvalueSolution EigenvalueInterpolator::solve_coupled(const std::vector<DirectionFrame>& frames,
                                                         const std::vector<EigenvalueTarget>& targets, EigenvalueSolver solver,
                                                         const std::vector<Vec3>& warm_start) {
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(volume_.cell_count());
  std::vector<CellId> constrained;
  for (const EigenvalueTarget& t : targets) constrained.push_back(t.cell);
  const std::vector<bool> pinned = cells_of_unconstrained_pieces(volume_, constrained);
  if (weights_.equilibrium > 0.0 && !(frames_of_equilibrium_ && same_frames(frames, *frames_of_equilibrium_))) {
    // The eq. 6 rows depend on the frames only: kept while they stay (control point edits).
    const double h = volume_.grid().cell_size_mm;
    SparseMatrix g_rows = eigenvalue_divergence_matrix(volume_, frames);
    drop_held_vertex_rows(g_rows, held_vertices_);
    const Eigen::SparseMatrix<double> g = g_rows;
    const Eigen::SparseMatrix<double> gtg = Eigen::SparseMatrix<double>(g.transpose()) * g;
    smoothness_and_equilibrium_ = smoothness_ + (weights_.equilibrium / (h * h * h * h)) * gtg;
    frames_of_equilibrium_ = frames;
  }
  Eigen::SparseMatrix<double> system = weights_.equilibrium > 0.0 ? smoothness_and_equilibrium_ : smoothness_;
  Vector rhs = Vector::Zero(n);
  for (const EigenvalueTarget& t : targets) {
    for (int i = 0; i < 3; ++i) {
      system.coeffRef(3 * t.cell + i, 3 * t.cell + i) += weights_.constraint;
      rhs[3 * t.cell + i] += weights_.constraint * t.eigenvalues_kPa[i];
    }
  }
  for (CellId c = 0; c < volume_.cell_count(); ++c)
    if (pinned[static_cast<std::size_t>(c)])
      for (int i = 0; i < 3; ++i) system.coeffRef(3 * c + i, 3 * c + i) += weights_.laplacian;  // no control point -> 0
  system.makeCompressed();

  EigenvalueSolution solution;
  Vector x = Vector::Zero(n);
  if (static_cast<Eigen::Index>(3 * warm_start.size()) == n)
    for (std::size_t c = 0; c < warm_start.size(); ++c) x.segment<3>(3 * static_cast<Eigen::Index>(c)) = warm_start[c];
  if (solver == EigenvalueSolver::cholesky) {
    Eigen::MatrixXd start = x;
    solve_with_kept_factor(system, rhs, start, solution.iterations);
    x = start.col(0);
  } else {
    const PlainCgOutcome cg = plain_conjugate_gradient(system, rhs, x, kPaperCgTolerance, kPaperCgMaxIterations);
    solution.iterations = cg.iterations;
    if (!(cg.relative_residual <= kPaperCgTolerance) || !x.allFinite())
      throw ComputeError(fmt::format("paper CG on the eigenvalue system did not converge: relative residual {:.3g} after {} "
                                     "iterations (tolerance {:.3g})",
                                     cg.relative_residual, cg.iterations, kPaperCgTolerance));
  }
  solution.eigenvalues_kPa.resize(static_cast<std::size_t>(volume_.cell_count()));
  for (CellId c = 0; c < volume_.cell_count(); ++c) solution.eigenvalues_kPa[static_cast<std::size_t>(c)] = x.segment<3>(3 * c);
  return solution;
}

}  // namespace cleave
