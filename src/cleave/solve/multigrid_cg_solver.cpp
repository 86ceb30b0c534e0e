#include "cleave/solve/multigrid_cg_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/conjugate_gradient.hpp"
#include "cleave/solve/multigrid_preconditioner.hpp"

namespace cleave {
namespace {

/// CG with the single-precision cycle runs in rounds of this many iterations. One that has not
/// converged after a round goes on from where it got: in single precision again while the round
/// reduced the residual at least kSingleRoundReduction-fold (the cycle works, the body just needs
/// many iterations: the incised tube at 129k cells needs 47), else with the double-precision cycle
/// (float rounding stalls it: the bench's incised abdomen, with free plugs on 3-2-1 supports,
/// then needs about 17 more).
constexpr int kSinglePrecisionMaxIterations = 40;
constexpr double kSingleRoundReduction = 10.0;

/// The loosest of a solve's two tolerances from which on CG multiplies with the operator in
/// single precision (see MultigridCgSolver::cg).
constexpr double kSinglePrecisionProductTolerance = 1e-6;

/// Iterations a stale solve may take beyond MultigridOptions::stale_solve_rebuild_factor times
/// the first solve's before its levels are rebuilt.
constexpr int kStaleExtraIterations = 10;

class MultigridCgSolver final : public LinearSolver {
 public:
  MultigridCgSolver(const SolveSettings& settings, const MultigridOptions& options) : settings_(settings), options_(options) {}

  void setup(const SparseMatrix& a, const LinkedVolume& topology) override {
    take_blocks_of(a);
    build(topology);
  }

  /// The scalar matrix is let go as soon as its blocks are made, before the levels are built:
  /// the set-up's peak holds one copy of the fine matrix fewer.
  void setup_taking(SparseMatrix&& a, const LinkedVolume& topology) override {
    take_blocks_of(a);
    {
      SparseMatrix released;
      released.swap(a);
    }
    build(topology);
  }

  void update_values(const SparseMatrix& a, const LinkedVolume& topology) override {
    // Compressed: the last row start is the entry count, so equal row starts mean equal sizes too.
    const bool same_pattern = a.isCompressed() && std::equal(pattern_row_start_.begin(), pattern_row_start_.end(),
                                                             a.outerIndexPtr(), a.outerIndexPtr() + a.rows() + 1);
    if (!same_pattern || rebuild_requested_ || stale_updates_ >= options_.max_stale_updates) {
      setup(a, topology);
      return;
    }
    refresh_block_values(a, a_blocks_);
    operator_ = nullptr;
    preconditioner_.refresh_fine_level(a_blocks_);
    ++stale_updates_;
    topology_ = &topology;
  }

  bool update_block_values(BlockSparseMatrix<double>& a, const LinkedVolume& topology) override {
    if (rebuild_requested_ || stale_updates_ >= options_.max_stale_updates || a.row_start != a_blocks_.row_start ||
        a.column != a_blocks_.column)
      return false;
    a_blocks_.values.swap(a.values);  // no 100 MB copy per time step at 44k cells
    operator_ = nullptr;
    preconditioner_.refresh_fine_level(a_blocks_);
    ++stale_updates_;
    topology_ = &topology;
    return true;
  }

  bool update_operator(const VertexOperator& a, const LinkedVolume& topology) override {
    if (rebuild_requested_ || stale_updates_ >= options_.max_stale_updates || a.rows() != rows_ ||
        preconditioner_.levels().size() < 2)
      return false;
    preconditioner_.use_fine_operator(a, a.inverse_diagonal_blocks());
    operator_ = &a;
    ++stale_updates_;
    topology_ = &topology;
    return true;
  }

  bool update_topology_operator(const VertexOperator& a, const LinkedVolume& topology,
                                const std::vector<VertexId>& origin_of_new) override {
    if (rebuild_requested_ || stale_updates_ >= options_.max_stale_updates || preconditioner_.levels().size() < 2 ||
        a.rows() != rows_ + 3 * static_cast<Eigen::Index>(origin_of_new.size()))
      return false;
    preconditioner_.replace_fine_level(a, a.inverse_diagonal_blocks(), origin_of_new, options_.smoother);
    operator_ = &a;
    rows_ = a.rows();
    // The matrix of the old topology is of no further use: a rebuild assembles the operator.
    a_blocks_ = BlockSparseMatrix<double>();
    pattern_row_start_.clear();
    ++stale_updates_;
    topology_ = &topology;
    return true;
  }

  bool setup_operator(const VertexOperator& a, const BlockSparseMatrix<double>& blocks, const LinkedVolume& topology) override {
    // Checked before anything is dropped: a refused set-up leaves the solver as it was.
    if (blocks.rows() != a.rows())
      throw InputError(fmt::format("multigrid: the block copy of the operator has {} rows; the operator has {}", blocks.rows(), a.rows()));
    // The old fine smoother's bound and vector: the new estimate continues them when the fine
    // level keeps its size (a rebuild for new values; 4 power iterations instead of 12).
    ChebyshevSmoother before;
    if (preconditioner_.levels().size() > 1) {
      before.lambda_max = preconditioner_.levels()[0].smoother.lambda_max;
      before.lambda_vector = preconditioner_.levels()[0].smoother.lambda_vector;
    }
    const std::vector<VertexId> no_copies;
    preconditioner_ = MultigridPreconditioner();  // the old levels go before the new ones are built
    a_blocks_ = BlockSparseMatrix<double>();
    pattern_row_start_.clear();
    rows_ = a.rows();
    preconditioner_ = build_multigrid_for_operator(a, blocks, topology, options_, ChebyshevWarmStart{&before, &no_copies});
    if (preconditioner_.uses_fine_operator()) {
      operator_ = &a;
    } else {  // one level: its factorization preconditions, CG multiplies with the blocks
      operator_ = nullptr;
      a_blocks_ = blocks;
    }
    topology_ = &topology;
    stale_updates_ = 0;
    baseline_iterations_ = -1;
    rebuild_requested_ = false;
    return true;
  }

  void update_topology(const SparseMatrix& a, const LinkedVolume& topology, const std::vector<VertexId>& origin_of_new) override {
    replace_fine_level(a, nullptr, topology, origin_of_new);
  }

  void update_topology_with_blocks(const SparseMatrix& a, const BlockSparseMatrix<double>& blocks, const LinkedVolume& topology,
                                   const std::vector<VertexId>& origin_of_new) override {
    if (blocks.rows() != a.rows())
      throw InputError(fmt::format("multigrid: the block copy of the new matrix has {} rows; the matrix has {}", blocks.rows(), a.rows()));
    replace_fine_level(a, &blocks, topology, origin_of_new);
  }

  SolveReport solve(const Vector& b, Vector& x) override {
    if (b.size() != rows_)
      throw InputError(fmt::format("multigrid: right-hand side has {} entries; the matrix set up has {} rows", b.size(), rows_));
    if (stale_updates_ == 0 || baseline_iterations_ < 0 || options_.stale_solve_rebuild_factor <= 0 || topology_ == nullptr)
      return track(solve_with(b, x, settings_));
    SolveSettings capped = settings_;
    capped.max_iterations = std::min(
        settings_.max_iterations,
        static_cast<int>(options_.stale_solve_rebuild_factor * baseline_iterations_) + kStaleExtraIterations);
    const SolveReport stale = solve_with(b, x, capped);
    if (stale.converged || stale.iterations >= settings_.max_iterations) return track(stale);
    // The kept levels no longer fit the matrix: rebuild them from its current values, go on from x.
    if (operator_ != nullptr) {
      setup_operator(*operator_, to_block_sparse<double>(operator_->assembled_matrix()), *topology_);
    } else {
      preconditioner_ = MultigridPreconditioner();
      build(*topology_);  // the blocks hold the current values (update_values and update_block_values keep them so)
    }
    const SolveSettings rest = continuation(settings_, stale, settings_.max_iterations - stale.iterations);
    SolveReport report = solve_with(b, x, rest);
    baseline_iterations_ = report.iterations;
    report.iterations += stale.iterations;
    report.initial_relative_residual = stale.initial_relative_residual;
    return report;
  }

  std::string_view name() const override { return "multigrid"; }

 private:
  void build(const LinkedVolume& topology) {
    preconditioner_ = build_multigrid(a_blocks_, topology, options_);
    topology_ = &topology;
    stale_updates_ = 0;
    baseline_iterations_ = -1;
    rebuild_requested_ = false;
  }

  /// After cuts divided vertices: keeps the coarse levels and replaces the fine one (or sets up
  /// when the levels cannot be kept). `blocks`: a's block copy when the caller has one.
  void replace_fine_level(const SparseMatrix& a, const BlockSparseMatrix<double>* blocks, const LinkedVolume& topology,
                          const std::vector<VertexId>& origin_of_new) {
    const Eigen::Index expected_rows = rows_ + 3 * static_cast<Eigen::Index>(origin_of_new.size());
    if (preconditioner_.levels().size() < 2 || a.rows() != expected_rows || !a.isCompressed() || rebuild_requested_ ||
        stale_updates_ >= options_.max_stale_updates) {
      setup(a, topology);
      return;
    }
    rows_ = a.rows();
    operator_ = nullptr;
    a_blocks_ = blocks != nullptr ? *blocks : to_block_sparse<double>(a);
    remember_pattern(a);
    preconditioner_.replace_fine_level(a_blocks_, origin_of_new, options_.smoother);
    ++stale_updates_;
    topology_ = &topology;
  }

  /// `settings` to go on from where `first` left x: the initial-residual rule refers to the
  /// caller's initial guess, so it becomes an absolute tolerance.
  static SolveSettings continuation(const SolveSettings& settings, const SolveReport& first, int iterations_left) {
    SolveSettings rest = settings;
    rest.max_iterations = iterations_left;
    rest.relative_tolerance = std::max(settings.relative_tolerance, settings.initial_residual_tolerance * first.initial_relative_residual);
    rest.initial_residual_tolerance = 0;
    rest.zero_start_when_better = false;  // x holds the first part's progress
    return rest;
  }

  /// CG with the cycle: single precision in rounds while they make progress, the double cycle
  /// once float rounding stalls a round (see kSinglePrecisionMaxIterations).
  SolveReport solve_with(const Vector& b, Vector& x, const SolveSettings& settings) {
    if (preconditioner_.precision() != CyclePrecision::single_precision) {
      SolveReport report = cg(b, x, settings);
      report.double_cycle_iterations = report.iterations;
      return report;
    }
    SolveSettings attempt = settings;
    attempt.max_iterations = std::min(settings.max_iterations, kSinglePrecisionMaxIterations);
    SolveReport single = cg(b, x, attempt);  // its initial residual stays the caller's (continuation)
    double round_start = single.initial_relative_residual;
    int round_iterations = single.iterations;
    // Another float round while the last one did iterations and cut the residual 10-fold (a
    // non-finite load reports zero residuals and no iterations: it stops here).
    while (!single.converged && round_iterations > 0 && single.iterations < settings.max_iterations &&
           single.relative_residual > 0 && kSingleRoundReduction * single.relative_residual <= round_start) {
      round_start = single.relative_residual;
      SolveSettings next = continuation(settings, single, settings.max_iterations - single.iterations);
      next.max_iterations = std::min(next.max_iterations, kSinglePrecisionMaxIterations);
      const SolveReport round = cg(b, x, next);
      round_iterations = round.iterations;
      single.iterations += round.iterations;
      single.relative_residual = round.relative_residual;
      single.converged = round.converged;
    }
    if (single.converged || single.iterations >= settings.max_iterations) return single;
    // Float rounding of an ill-conditioned A: go on from x in double, within the budget.
    preconditioner_.use_double_precision(a_blocks_);
    SolveReport report = cg(b, x, continuation(settings, single, settings.max_iterations - single.iterations));
    report.double_cycle_iterations = report.iterations;
    report.iterations += single.iterations;
    report.initial_relative_residual = single.initial_relative_residual;
    return report;
  }

  /// CG with the current matrix: the operator when the last update gave one, else the blocks.
  /// With the operator, the single-precision cycle and a loose tolerance (the dynamic step's
  /// 1e-5 of its predictor's residual), the iterations' products are single precision too
  /// (SolveSettings::single_precision_products): their rounding makes the recurrence's residual
  /// drift from the true one by ~1e-7 of the products, well below that tolerance (44k tube: the
  /// same iterations and residuals, 5-10 % less time per step). Tighter tolerances and the double
  /// cycle get double products: there the drift costs restarts and iterations.
  SolveReport cg(const Vector& b, Vector& x, const SolveSettings& settings) {
    if (operator_ != nullptr) {
      SolveSettings with_products = settings;
      with_products.single_precision_products =
          preconditioner_.precision() == CyclePrecision::single_precision &&
          std::max(settings.relative_tolerance, settings.initial_residual_tolerance) >= kSinglePrecisionProductTolerance;
      return preconditioned_cg(*operator_, b, x, preconditioner_, with_products);
    }
    return preconditioned_cg(a_blocks_, b, x, preconditioner_, settings);
  }

  /// Drops the levels and the old matrix, then makes the block copy of `a` (compressed first when
  /// it is not) that the levels are built from.
  void take_blocks_of(const SparseMatrix& a) {
    if (!a.isCompressed()) {
      SparseMatrix compressed = a;
      compressed.makeCompressed();
      take_blocks_of(compressed);
      return;
    }
    preconditioner_ = MultigridPreconditioner();
    operator_ = nullptr;
    a_blocks_ = BlockSparseMatrix<double>();  // the old copy goes before the new one is made
    a_blocks_ = to_block_sparse<double>(a);
    remember_pattern(a);
    rows_ = a.rows();
  }

  /// The compressed scalar pattern's row starts, against which update_values() checks that a new
  /// matrix has the pattern the blocks were made from (the scalar matrix itself is not kept).
  void remember_pattern(const SparseMatrix& a) { pattern_row_start_.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.rows() + 1); }

  /// Remembers the first solve's iterations after a build; a solve far above them asks for a
  /// rebuild at the next update.
  /// A solve stopped by an iteration budget counts the iterations it would have needed at its rate.
  SolveReport track(const SolveReport& report) {
    double needed = report.iterations;
    if (!report.converged && report.initial_relative_residual > 0) {
      // CG's stopping rule relative to the start: the looser of its two tolerances.
      const double target = std::max(settings_.initial_residual_tolerance, settings_.relative_tolerance / report.initial_relative_residual);
      if (target < 1) needed = iterations_at_reached_rate(report, target);
    }
    if (baseline_iterations_ < 0) baseline_iterations_ = static_cast<int>(std::min(std::ceil(needed), 1e6));
    else if (needed > options_.stale_iteration_growth * baseline_iterations_ + 2) rebuild_requested_ = true;
    return report;
  }

  SolveSettings settings_;
  MultigridOptions options_;
  BlockSparseMatrix<double> a_blocks_;  ///< the current matrix as block CSR: what the levels are built from and CG multiplies with ...
  const VertexOperator* operator_ = nullptr;  ///< ... unless the last update gave the matrix as an operator
  Eigen::Index rows_ = 0;  ///< of the current matrix (a_blocks_ is empty after a topology update by operator)
  std::vector<SparseMatrix::StorageIndex> pattern_row_start_;  ///< see remember_pattern()
  MultigridPreconditioner preconditioner_;
  int stale_updates_ = 0;         ///< update_values() calls since the hierarchy was built
  int baseline_iterations_ = -1;  ///< iterations of the first solve after the build
  bool rebuild_requested_ = false;
  const LinkedVolume* topology_ = nullptr;  ///< of the last setup / update (the caller keeps it alive while solving)
};

}  // namespace

double iterations_at_reached_rate(const SolveReport& report, double target_reduction) {
  if (report.converged || !(target_reduction > 0 && target_reduction < 1)) return report.iterations;
  const double reached = report.initial_relative_residual > 0 ? report.relative_residual / report.initial_relative_residual : 1.0;
  if (report.iterations <= 0 || !(reached < 1) || !std::isfinite(reached)) return std::numeric_limits<double>::infinity();
  if (reached <= target_reduction) return report.iterations;
  return report.iterations * std::log(target_reduction) / std::log(reached);
}

std::unique_ptr<LinearSolver> make_multigrid_cg_solver(const SolveSettings& settings, const MultigridOptions& options) {
  return std::make_unique<MultigridCgSolver>(settings, options);
}

}  // namespace cleave
