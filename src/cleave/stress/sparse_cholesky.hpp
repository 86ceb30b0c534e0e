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
#include <vector>

namespace cleave {

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;

  void factorize(const Eigen::SparseMatrix<double>& a);
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  /// a0^-1 b with a single-precision copy of the factor (made by the first call after each
  /// factorization: half the factor's bytes to keep and to stream, so about half the time of
  /// solve). Its error is about the float rounding times the condition number: for a
  /// preconditioner whose result is checked in double (the equilibration's CG), not as a solve.
  /// ComputeError for a non-finite result.
  Eigen::VectorXd solve_single_precision(const Eigen::VectorXd& b) const;
  /// Same, followed by kRefinementSteps of iterative refinement against `a` (the factorized
  /// matrix): the design systems (L^T L, condition ~ n^2) lose digits in a plain solve.
  Eigen::MatrixXd solve_refined(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b) const;
  static constexpr int kRefinementSteps = 2;
  /// Solves a x = b for a matrix `a` with the pattern of the factorized one (SPD, both triangles
  /// stored, as for factorize), starting from x (the previous solution). When `a` has exactly the values of the factorized matrix (an edit that
  /// changed only the right-hand side) this is one solve with the factor, refined until the
  /// tolerance is met (at most kRefinementSteps steps; usually one). Otherwise (a
  /// design edit changed some values) it runs conjugate gradients preconditioned with the kept
  /// factor, column by column: an edit that changes a few constraint rows is a low-rank change, so
  /// CG needs about as many iterations as the rank of the change and no new factorization is
  /// needed. It gives up as soon as it is cheaper to factorize: when only d diagonal entries
  /// changed (constraints added, moved or removed: a rank-d update, about d + 1 iterations) and
  /// d + 1 solves per column cost more than the last factorization plus a refined solve, it does
  /// not start; otherwise, from its 4th iteration on (its (d + 2)th for a diagonal change), it
  /// projects its remaining iterations from the residual's mean rate and stops when their
  /// measured cost exceeds that of a new factor, or when they would exceed max_iterations.
  /// Before that CG, a change of diagonal entries only (a = a0 + E D E^T, E the unit columns of
  /// the changed rows) is solved exactly with the kept factor by the Woodbury identity
  ///   a^-1 = a0^-1 - G_E (I + D E^T G_E)^-1 D G_E^T,   G = a0^-1 [e_r ...],
  /// with G's columns kept across calls while the factor stays.
  /// G also gets the columns of the rows where b is not zero (the design's right-hand sides live
  /// on the constrained cells only), so that a0^-1 b = G b_rows needs no solve either: once the
  /// columns of an edit's rows exist (an edit back and forth, a value typed at a placed control
  /// point: also for a right-hand-side-only change), the solve is dense algebra on G and a
  /// residual check. Its rounding error sits on the changed rows, so G's columns also refine it;
  /// a solve with the factor refines only what they cannot (see kMaxLowRankRows).
  /// Changed rows without columns may instead be solved by the sparse update (UpdatePolicy), and a
  /// system solved before with this factor gets its remembered solution (remembered_solves).
  /// Returns true when every column reached the tolerance: CG a relative residual
  /// ||b - a x|| <= relative_tolerance ||b||, the solves with the factor and the Woodbury update a
  /// normwise backward error ||b - a x|| / (||a||_1 ||x|| + ||b||) <= relative_tolerance (the
  /// level a backward stable direct solve reaches; the rounding of a x, large where x is large,
  /// is not held against x). False (x unspecified) when there is no factor, the pattern differs,
  /// or CG gave up: then factorize(a).
  bool solve_with_current_factor(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, Eigen::MatrixXd& x,
                                 double relative_tolerance, int max_iterations) const;
  /// Whether the factor is of exactly `a` (same pattern and values).
  bool factor_is_of(const Eigen::SparseMatrix<double>& a) const;
  /// Preconditioned CG iterations run by the last solve_with_current_factor (all columns).
  int last_iterations() const { return last_iterations_; }
  /// Columns of G kept for the Woodbury update (0 after a factorization).
  Eigen::Index low_rank_rows() const;
  /// Calls of solve_with_current_factor answered by the Woodbury update.
  int low_rank_solves() const { return low_rank_solves_; }
  /// The Woodbury update is used for at most this many changed diagonal rows since the last
  /// factorization, and while G (n x rows doubles) stays below kMaxLowRankBytes.
  static constexpr Eigen::Index kMaxLowRankRows = 1024;
  static constexpr double kMaxLowRankBytes = 256.0 * 1024 * 1024;
  /// Refinement steps of the Woodbury solve (each one solve with the kept factor) before it gives up.
  static constexpr int kLowRankRefinementSteps = 3;
  /// Solves with the factor (each over all columns of its right-hand side) that the last
  /// solve_with_current_factor ran: 0 when G answered alone.
  int last_factor_solves() const { return last_factor_solves_; }
  /// Numeric factorizations that could reuse the previous symbolic analysis.
  int reused_analyses() const { return reused_; }

  /// How a diagonal edit whose changed rows lack columns of G is solved with the kept factor.
  /// `cheaper` (the default) takes whichever of the two is estimated faster from the last
  /// measured costs; the others force one (tests, comparisons).
  ///  - columns: buy the missing columns of G (a full solve per column; kept for later edits);
  ///  - sparse: the forward-substituted unit columns W = L^-1 P E, made only on the supernodes
  ///    above the changed rows (a stroke's 142 rows reach 13 % of the rows at 45k cells), then
  ///      a^-1 b = P^T L^-T (y - W (I + D W^T W)^-1 D W^T y),   y = L^-1 P b,
  ///    one forward substitution of b (over the supernodes above its rows) and one back
  ///    substitution, before which the residual the update leaves on the changed rows is
  ///    corrected (x on their neighbours by SupernodalSubstitution::backward_rows); refined by
  ///    the same formula only if that is not enough. W's columns are kept for every row changed
  ///    since the factorization (ForwardColumnBatches: one batch per edit, on the rows it reaches),
  ///    so an edit makes only its new rows' columns (a stroke dragged one cell further: that
  ///    cell's) and the products W^T W of pairs no earlier edit used together
  ///    (docs/stress-design.md, "Sparse update").
  enum class UpdatePolicy { cheaper, columns, sparse };
  void set_update_policy(UpdatePolicy policy) { policy_ = policy; }
  /// Calls of solve_with_current_factor answered by the sparse update (a subset of low_rank_solves).
  int sparse_update_solves() const { return sparse_update_solves_; }
  /// Columns of W the sparse update has made since construction (each a changed row's first use).
  int sparse_columns_made() const { return sparse_columns_made_; }
  /// Calls of solve_with_current_factor answered by a remembered solution: the last two systems
  /// solved with this factor (without CG: the factorized matrix or a diagonal change of it) are
  /// kept with their right-hand sides, so that an undo and a redo, or a stroke dragged back and
  /// forth, need no solve. Forgotten at every factorization. (The solution met the tolerance of
  /// the call that made it; each design system keeps one tolerance.)
  int remembered_solves() const { return remembered_solves_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  /// The Woodbury update of solve_with_current_factor: true when x reached the tolerance.
  /// Gives up (false) before solving when its new columns would cost more than refactor_seconds,
  /// or, without new_columns_allowed, when G lacks a column it needs.
  bool solve_diagonal_update(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, Eigen::MatrixXd& x,
                             double relative_tolerance, double refactor_seconds, bool new_columns_allowed) const;
  /// The sparse update (see UpdatePolicy) over the changed rows `changed`, a = a0 + diag(change).
  bool solve_sparse_update(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, Eigen::MatrixXd& x,
                           double relative_tolerance, const std::vector<Eigen::Index>& changed, const Eigen::VectorXd& change) const;
  /// x = the remembered solution of the system with this diagonal and b (counted in
  /// remembered_solves); false when there is none.
  bool recall(const Eigen::VectorXd& a_diagonal, const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const;
  /// Seconds the sparse update of `rows` changed rows and `columns` right-hand sides is expected to take.
  double sparse_update_seconds(std::size_t rows, Eigen::Index columns) const;
  UpdatePolicy policy_ = UpdatePolicy::cheaper;
  mutable int sparse_update_solves_ = 0;
  mutable int sparse_columns_made_ = 0;
  mutable int remembered_solves_ = 0;
  int reused_ = 0;
  mutable int last_iterations_ = 0;
  mutable int last_factor_solves_ = 0;
  mutable int low_rank_solves_ = 0;
};

}  // namespace cleave
