#pragma once
// The eigenvalue fields (paper section 6.2): per cell lambda = (Langer, cross, normal) in kPa,
//   min  w_L |L lambda|^2 + w_C |C lambda - lambda0|^2 + w_E |T (d sigma/d lambda) lambda / h^2|^2
// (eq. 9; pieces of the body without a control point get lambda = 0), solved on the normal equations
// A^T A lambda = A^T b. The equilibrium rows are divided by h^2 (T is in mm^2) so that every term
// is a stress in kPa. Free vertices are all vertices (the design is for the unsupported body).
//
//   EigenvalueInterpolator interp(volume, weights);                // L^T L (x) I3 once per topology
//   EigenvalueSolution s = interp.solve(frames, targets, EigenvalueSolver::cholesky, warm_start);
//
// Solvers: `cholesky` (default): CHOLMOD supernodal Cholesky; the factor is kept between calls
// (the pattern of A^T A depends only on the topology). After an edit:
//   - same matrix, other right-hand side (a control point's values changed): one refined solve
//     with the kept factor;
//   - other matrix values (a control point added, moved or deleted: a few diagonal entries, a
//     low-rank change; or, with w_E > 0, new frames): CG preconditioned with the kept factor from
//     `warm_start`; the new system is factorized only when that CG would cost more than a new
//     factor (SparseCholesky::solve_with_current_factor projects it from the residual's rate).
// Without the equilibrium rows (w_E = 0, the default) the three eigenvalue fields are
// independent and do not depend on the frames: one scalar system of n_c unknowns with three
// right-hand sides (a third of the unknowns, a factor about 4 times smaller than the coupled
// 3 n_c system). `paper_cg`: the paper's plain CG on the coupled A^T A (one thread, no
// preconditioner), started from `warm_start` when it has the right size, to relative residual
// 1e-12; ComputeError when it does not get there.
// Never returns a non-finite eigenvalue: ComputeError "eigenvalue interpolation: ..." instead.
#include <optional>
#include <vector>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"
#include "cleave/stress/control_point_targets.hpp"
#include "cleave/stress/direction_frames.hpp"
#include "cleave/stress/sparse_cholesky.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave {

struct EigenvalueSolution {
  std::vector<Vec3> eigenvalues_kPa;  ///< per cell: Langer, cross, normal
  int iterations = 0;                 ///< CG iterations (plain CG; for `cholesky`, CG with the kept factor, 0 = direct)
};

class EigenvalueInterpolator {
 public:
  /// `held_vertices`: no eq. 6 rows there (they carry reactions); empty = free body.
  EigenvalueInterpolator(const LinkedVolume& volume, const DesignWeights& weights, std::vector<VertexId> held_vertices = {});
  EigenvalueSolution solve(const std::vector<DirectionFrame>& frames, const std::vector<EigenvalueTarget>& targets,
                           EigenvalueSolver solver, const std::vector<Vec3>& warm_start = {});
  static constexpr double kReuseTolerance = 1e-13;  ///< of the solve with the kept factor (SparseCholesky::solve_with_current_factor)
  /// Hard cap of the CG with the kept factor; it usually gives up earlier, on its cost estimate.
  static constexpr int kMaxReuseIterations = 400;
  /// Numeric factorizations done so far by the `cholesky` solver.
  int factorizations() const { return factorizations_; }

 private:
  EigenvalueSolution solve_scalar(const std::vector<EigenvalueTarget>& targets, const std::vector<Vec3>& warm_start);
  EigenvalueSolution solve_coupled(const std::vector<DirectionFrame>& frames, const std::vector<EigenvalueTarget>& targets,
                                   EigenvalueSolver solver, const std::vector<Vec3>& warm_start);
  /// x: the warm start on entry, the solution on exit; iterations: CG iterations with the kept factor.
  void solve_with_kept_factor(const Eigen::SparseMatrix<double>& system, const Eigen::MatrixXd& rhs, Eigen::MatrixXd& x,
                              int& iterations);
  const LinkedVolume& volume_;
  DesignWeights weights_;
  std::vector<VertexId> held_vertices_;
  Eigen::SparseMatrix<double> smoothness_;         ///< w_L (L^T L) (x) I3, ColMajor
  Eigen::SparseMatrix<double> scalar_smoothness_;  ///< w_L L^T L, ColMajor (w_E = 0)
  /// w_E > 0: smoothness_ + w_E G^T G / h^4 for the frames it was built with (kept across control point edits)
  Eigen::SparseMatrix<double> smoothness_and_equilibrium_;
  std::optional<std::vector<DirectionFrame>> frames_of_equilibrium_;
  SparseCholesky cholesky_;
  int factorizations_ = 0;
};

}  // namespace cleave
