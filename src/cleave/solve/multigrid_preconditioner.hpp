#pragma once
// The cut-aware geometric multigrid V-cycle used as CG preconditioner (paper section 6.4 after
// Dick, Georgii & Westermann 2011). Levels come from the linked volume by repeated 2x2x2
// coarsening with cell replication (coarsen_grid_level.hpp), so pieces separated by cuts stay
// separated on every level; coarse operators are Galerkin products P^T A P with fixed dofs left
// out of P (galerkin_operator.hpp); Chebyshev / block-Jacobi smoothing before and after the
// coarse correction (chebyshev_smoother.hpp); a sparse Cholesky solve on the coarsest level
// (coarsest_factor.hpp).
// The cycle runs in single precision on block CSR copies of the operators (block_sparse_matrix.hpp).
//
//   MultigridPreconditioner m = build_multigrid(a, volume);   // a: 3 n_v x 3 n_v on volume's vertices
//   m.apply(r, z);                                            // z = one V-cycle on A z = r from z = 0
//
// Inputs: a symmetric positive definite matrix (fixed dofs as identity rows), rows 3 v + axis for
// the volume's current vertices, as block CSR or as compressed RowMajor scalar CSR (converted to
// blocks once). Neither is referenced after the build: the levels keep their own copies in the
// cycle's precision. Throws InputError when the sizes do not match.
// apply() uses internal work vectors: one apply at a time per object.
#include <memory>
#include <type_traits>
#include <vector>

#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/chebyshev_smoother.hpp"
#include "cleave/solve/coarsen_grid_level.hpp"
#include "cleave/solve/conjugate_gradient.hpp"
#include "cleave/solve/weak_piece_solves.hpp"

namespace cleave {

/// The arithmetic of the V-cycle (the outer CG is always double).
enum class CyclePrecision {
  single_precision,  ///< float operators and vectors: half the bytes; fine where A is well conditioned
  double_precision,  ///< for ill-conditioned systems (a free piece held by 3-2-1 supports) where
                     ///< float rounding of A hides its smallest eigenvalues
};

struct MultigridOptions {
  int coarsest_max_dofs = 2000;  ///< stop coarsening once a level has this few free dofs
  /// ... or once a coarse level's Cholesky factor would hold at most this share of the fine
  /// matrix's nonzeros (a solve with it streams about 5 % of a V-cycle's bytes) and cost at most
  /// coarsest_factor_flops_per_fine_entry flops per fine entry to factor (about five fine
  /// products). Coarse cells much wider than a thin shell is thick stiffen its bending, so a
  /// shell is best served by stopping early, and its factor is cheap: the abdomen at 45k cells (a
  /// shell 4-6 cells thick) stops at 4,695 dofs (1.3 % of the fine entries, 13 ms to factor) and
  /// needs 21 preview iterations instead of 32 one level deeper. A solid's factor fills in: the
  /// 44k tube's level of 7,320 dofs would hold 8 % (55 ms), so it goes one level deeper, as the
  /// dof count alone made it. 0: by the dof count only.
  double coarsest_factor_share = 0.05;
  double coarsest_factor_flops_per_fine_entry = 10.0;
  double min_coarsening_ratio = 0.85;    ///< stop when a level keeps more than this share of dofs
  int max_levels = 12;
  ChebyshevOptions smoother;
  /// The Chebyshev degree on the coarse levels (the fine level's is smoother.degree). The coarse
  /// correction's accuracy bounds the iterations: on the 44k tube's dynamic step 12.5 / 10.2 /
  /// 8.8 / 8.7 / 8.9 CG iterations at coarse degree 1 / 2 / 3 / 4 / 10. A level-1 pass reads a
  /// seventh of a fine product's bytes, but with its vector work degree 3 costs about what it
  /// saves on the bench's step (equal times), 0.94x in the step harness; the preview needs fewer
  /// iterations (62 -> 51 on the 350k-cell tube).
  int coarse_degree = 3;
  /// The coarse levels' smoothing range (lambda_max over the lower end of the interval they damp;
  /// the fine level's is smoother.smoothing_range), so that the fine level's can differ: the
  /// real-time step smooths its fine level with one damped block-Jacobi step (degree 1, range 4).
  double coarse_smoothing_range = 8.0;
  /// The cycle's precision at build; multigrid_cg_solver falls back to double when float rounding
  /// stalls CG with the single-precision cycle.
  CyclePrecision precision = CyclePrecision::single_precision;
  /// update_values() keeps the coarse levels of an older matrix for at most this many updates
  /// (only the fine level's matrix and block diagonal follow every update) ... A rebuild costs
  /// 3-4 steps of the 44k tube (0.5 s CPU) and its first solve needed as many iterations as the
  /// 16th stale one there (9): the iteration rule below, not this count, is what rebuilds.
  int max_stale_updates = 64;
  /// ... and rebuilds them sooner when a solve needs more than this factor (plus 2) times the
  /// iterations of the first solve after the last rebuild.
  double stale_iteration_growth = 1.3;
  /// A solve with kept (stale) levels that needs more than this factor times the first solve's
  /// iterations (plus 10) rebuilds them from the current values mid-solve and goes on from where
  /// it got: corotated free pieces (the studio's 108 removed plugs at 45k cells) made one stale
  /// solve take 1,426 iterations. 0: never rebuild mid-solve.
  double stale_solve_rebuild_factor = 3.0;
  /// Exact solves on each level's weakly linked pieces (weak_piece_solves.hpp) before and after
  /// the coarse correction: the incised tube's preview needs 15-17 iterations from 44k to 350k
  /// cells with them, 29-50 without. weak_pieces.max_links = 0 turns them off.
  WeakPieceOptions weak_pieces;
};

/// A level's operator and work vectors in the cycle's precision.
template <typename Scalar>
struct CycleData {
  BlockSparseMatrix<Scalar> blocks;  ///< the level's operator as block CSR (all levels but the coarsest)
  mutable Eigen::Matrix<Scalar, Eigen::Dynamic, 1> rhs, solution, residual;
  mutable ChebyshevWork<Scalar> work;
};

/// One level: its operator, smoother, and the prolongation from the next coarser level.
struct MultigridLevel {
  SparseMatrix matrix;              ///< coarse levels only (level 0 keeps its operator as blocks only)
  std::vector<std::uint8_t> fixed;  ///< per dof: identity row
  ChebyshevSmoother smoother;
  Prolongation from_coarser;        ///< empty on the coarsest level
  WeakPieceSolves weak_pieces;      ///< empty on the coarsest level and where the level has none
  CycleData<float> single;          ///< filled when the cycle runs in single precision
  CycleData<double> twin;           ///< filled when it runs in double precision

  template <typename Scalar>
  const CycleData<Scalar>& data() const {
    if constexpr (std::is_same_v<Scalar, float>) return single;
    else return twin;
  }
};

class CoarsestFactor;

class MultigridPreconditioner final : public Preconditioner {
 public:
  MultigridPreconditioner();
  ~MultigridPreconditioner() override;
  MultigridPreconditioner(MultigridPreconditioner&&) noexcept;
  MultigridPreconditioner& operator=(MultigridPreconditioner&&) noexcept;

  void apply(const Vector& r, Vector& z) const override;

  CyclePrecision precision() const { return precision_; }
  /// Switches the cycle to double precision; `fine` is the current fine matrix (block CSR, the
  /// pattern built from, possibly newer values).
  void use_double_precision(const BlockSparseMatrix<double>& fine);

  /// Gives the fine level's smoother the values of `a` (the matrix built from, as block CSR,
  /// with new values: same pattern and fixed dofs) and their block diagonal; the coarse levels,
  /// the smoothers' eigenvalue bounds and the coarsest factorization stay those of the older
  /// matrix.
  void refresh_fine_level(const BlockSparseMatrix<double>& a);

  /// From now on the fine level applies `a` without its matrix (the dynamic step's system with
  /// new values, same topology: fem/corotated_system_operator.hpp; referenced, it must outlive
  /// the use) and smooths with `a`'s block diagonal `inverse_diagonal`; the coarse levels, the
  /// smoothers' eigenvalue bounds and the coarsest factorization stay, as in refresh_fine_level.
  /// Such a fine level has no rows to solve its weak pieces with: it smooths without them (the
  /// coarse levels keep theirs). refresh_fine_level and replace_fine_level go back to the fine
  /// level's blocks.
  void use_fine_operator(const VertexOperator& a, std::vector<Mat3> inverse_diagonal);
  bool uses_fine_operator() const { return fine_operator_ != nullptr; }

  /// Replaces the fine level after cuts divided vertices (LinearSolver::update_topology): `a` is
  /// the new fine matrix as block CSR (copied in the cycle's precision), vertex `n + i` of it a
  /// copy of the old fine vertex `origin_of_new[i]`. Each copy gets its origin's prolongation
  /// row; the fine level's fixed dofs, block diagonal and eigenvalue bound are those of `a`; the
  /// coarse levels and the coarsest factorization stay. Needs at least two levels (throws
  /// InputError otherwise, and for origins or sizes that do not fit). The fine level's weak
  /// pieces were found on the old cells and are dropped until the next build.
  void replace_fine_level(const BlockSparseMatrix<double>& a, const std::vector<VertexId>& origin_of_new,
                          const ChebyshevOptions& smoother);

  /// replace_fine_level for the new fine matrix applied without its values (the dynamic step's
  /// system after a cut): the fine level applies `a` (referenced, it must outlive the use) with
  /// its D^-1 `inverse_diagonal` and fixed dofs, its eigenvalue bound by power iteration on `a`;
  /// the coarse levels and the coarsest factorization stay. Throws InputError as replace_fine_level.
  void replace_fine_level(const VertexOperator& a, std::vector<Mat3> inverse_diagonal, const std::vector<VertexId>& origin_of_new,
                          const ChebyshevOptions& smoother);

  /// Level 0 is the fine level; the last level is solved directly.
  const std::vector<MultigridLevel>& levels() const { return levels_; }
  /// The Galerkin operator of a coarse level (1 and up; the fine level's matrix is not kept as
  /// scalar CSR: InputError for level 0 and for levels past the last).
  const SparseMatrix& coarse_operator(std::size_t level) const;

 private:
  friend MultigridPreconditioner build_levels(const BlockSparseMatrix<double>& a, const VertexOperator* fine_operator,
                                              const ChebyshevWarmStart& fine_warm, const LinkedVolume& volume,
                                              const MultigridOptions& options);
  template <typename Scalar>
  void cycle(std::size_t level) const;
  template <typename Scalar, typename Matrix>
  void smooth_around_coarse_correction(std::size_t level, const Matrix& a) const;
  template <typename Scalar>
  void allocate_cycle();
  /// Gives the fine vertices n + i the prolongation rows of their origins origin_of_new[i]
  /// (`new_rows`: the new fine level's row count, for the check). Checks everything before it
  /// changes anything: on InputError the levels are as they were.
  void extend_fine_prolongation(const std::vector<VertexId>& origin_of_new, Eigen::Index new_rows);

  const VertexOperator* fine_operator_ = nullptr;  ///< when set, the fine level's operator instead of its blocks
  std::vector<MultigridLevel> levels_;
  std::unique_ptr<CoarsestFactor> coarsest_;
  CyclePrecision precision_ = CyclePrecision::single_precision;
};

MultigridPreconditioner build_multigrid(const BlockSparseMatrix<double>& a, const LinkedVolume& volume,
                                        const MultigridOptions& options = {});
/// The same from scalar CSR (compressed, RowMajor; InputError otherwise).
MultigridPreconditioner build_multigrid(const SparseMatrix& a, const LinkedVolume& volume, const MultigridOptions& options = {});
/// The levels of `a` whose fine level applies `fine` (the same matrix without its values: the
/// dynamic step's corotated system, fem/corotated_system_operator.hpp; referenced, it must
/// outlive the use) from the start, as after use_fine_operator: `a` serves the Galerkin product
/// of the first coarse level only, and no copy of it is kept (the float copy alone is 50 MB at
/// 44k cells). The fine level has no weak pieces (they need its rows; the step's iterations do
/// not), so after a cut the build skips their search and factorization, which took 150 ms of a
/// 44k tube's rebuild. A hierarchy of one level keeps a's factorization and does not apply
/// `fine` (uses_fine_operator() false). The fine level's fixed dofs are `fine`'s. `fine_warm`: the
/// fine smoother of the hierarchy this one replaces, whose lambda_max estimate the new one
/// continues (a rebuild of the same topology with new values; ChebyshevWarmStart). InputError as
/// build_multigrid, and when `fine`'s rows or fixed flags are not as many as a's rows.
MultigridPreconditioner build_multigrid_for_operator(const VertexOperator& fine, const BlockSparseMatrix<double>& a,
                                                     const LinkedVolume& volume, const MultigridOptions& options = {},
                                                     const ChebyshevWarmStart& fine_warm = {});

/// x_fine += P x_coarse on free fine dofs (fixed dofs are not moved).
void prolongate_add(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Vector& coarse, Vector& fine);
void prolongate_add(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Eigen::VectorXf& coarse,
                    Eigen::VectorXf& fine);
/// coarse = P^T fine, leaving fixed fine dofs out.
void restrict_to_coarse(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Vector& fine, Vector& coarse);
void restrict_to_coarse(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Eigen::VectorXf& fine,
                        Eigen::VectorXf& coarse);

}  // namespace cleave
