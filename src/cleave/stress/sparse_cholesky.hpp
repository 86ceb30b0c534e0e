#pragma once
// Sparse Cholesky factorization of a symmetric positive definite matrix (CHOLMOD, supernodal),
// keeping the symbolic analysis while the sparsity pattern stays the same: the design's systems
// change values after every edit but never their pattern, so each update is numeric only.
//
//   SparseCholesky chol;
//   chol.factorize(a);            // a: SPD, ColMajor, both triangles stored (only the lower is read)
//   Eigen::MatrixXd x = chol.solve(b);
//
// Throws ComputeError when the matrix is not positive definite.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>

namespace cleave {

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;

  void factorize(const Eigen::SparseMatrix<double>& a);
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  /// Same, followed by kRefinementSteps of iterative refinement against `a` (the factorized
  /// matrix): the design systems (L^T L, condition ~ n^2) lose digits in a plain solve.
  Eigen::MatrixXd solve_refined(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b) const;
  static constexpr int kRefinementSteps = 2;
  /// Solves a x = b for a matrix `a` with the pattern of the factorized one but other values
  /// (a design edit), by conjugate gradients preconditioned with the current factor, column by
  /// column, starting from x (the previous solution). An edit that changes a few constraint rows
  /// is a low-rank change, so CG needs about as many iterations as the rank of the change and no
  /// new factorization is needed. Returns true when every column reached
  /// ||b - a x|| <= relative_tolerance ||b|| within max_iterations; false (x unspecified) when
  /// there is no factor, the pattern differs, or CG did not get there (it stops after a quarter of
  /// max_iterations when the residual is still above sqrt(relative_tolerance)): then factorize(a).
  bool solve_with_current_factor(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, Eigen::MatrixXd& x,
                                 double relative_tolerance, int max_iterations) const;
  /// Numeric factorizations that could reuse the previous symbolic analysis.
  int reused_analyses() const { return reused_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int reused_ = 0;
};

}  // namespace cleave
