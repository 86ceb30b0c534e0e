// GCC 12 reports -Wnull-dereference inside Eigen (sparse Ref construction, vector dot products)
// after inlining: a false positive for possibly-empty vectors. Silenced for this file's headers.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "cleave/stress/sparse_cholesky.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/LU>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/core/recent_results.hpp"
#include "cleave/solve/forward_column_batches.hpp"
#include "cleave/solve/supernodal_substitution.hpp"

namespace cleave {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

/// CG with the kept factor projects its remaining work from this iteration on at the earliest.
constexpr int kFirstProjectedIteration = 4;

/// New columns of G may cost this many refactorizations: unlike a new factor they are kept, and
/// every later edit on their rows (a stroke moved back, undo and redo, values typed at placed
/// control points) is then solved without a solve with the factor. A stroke of the abdomen at
/// 45k cells changes 142 rows (0.7 s of columns once, against 0.7-0.8 s of a refactorization at
/// every edit), and its right-hand side has 86 more.
constexpr double kColumnBudget = 4.0;

/// A refinement of the Woodbury solve by G's columns alone goes on while each step reduces the
/// residual by at least this factor.
constexpr double kColumnRefinementGain = 10.0;

/// max |a_ij| summed over a column: the 1-norm of a, for a symmetric matrix also its infinity-norm,
/// a bound of its 2-norm.
double norm_1(const Eigen::SparseMatrix<double>& a) {
  double norm = 0.0;
  for (Eigen::Index j = 0; j < a.outerSize(); ++j) {
    double column = 0.0;
    for (int k = a.outerIndexPtr()[j]; k < a.outerIndexPtr()[j + 1]; ++k) column += std::abs(a.valuePtr()[k]);
    norm = std::max(norm, column);
  }
  return norm;
}

/// The normwise backward error of x, the largest over the columns of
///   ||b - a x|| / (||a|| ||x|| + ||b||):
/// the relative change of a and b that x solves exactly. A solve with a backward stable factor
/// reaches a few units of rounding; unlike ||b - a x|| / ||b|| it does not count the rounding of
/// a x itself (large where x is large) against the solution.
double backward_error(double a_norm, const Eigen::MatrixXd& r, const Eigen::MatrixXd& x, const Eigen::MatrixXd& b) {
  double worst = 0.0;
  for (Eigen::Index col = 0; col < b.cols(); ++col) {
    const double scale = a_norm * x.col(col).norm() + b.col(col).norm();
    const double r_norm = r.col(col).norm();
    if (r_norm > 0.0) worst = std::max(worst, scale > 0.0 ? r_norm / scale : std::numeric_limits<double>::infinity());
  }
  return worst;
}

/// r = b - a x over the rows [begin, end) of a symmetric a stored whole (ColMajor: its columns are
/// its rows), x with its rows contiguous; kColumns fixed (the design's 1, 3 and 6 right-hand sides,
/// vectorised) or Eigen::Dynamic.
template <int kColumns, typename RowMajorMatrix>
void symmetric_residual_rows(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, const RowMajorMatrix& x_rows,
                             Eigen::Index begin, Eigen::Index end, RowMajorMatrix& r) {
  using Row = Eigen::Matrix<double, 1, kColumns>;
  const Eigen::Index columns = x_rows.cols();
  Row sum(columns);
  for (Eigen::Index j = begin; j < end; ++j) {
    sum.setZero();
    for (int k = a.outerIndexPtr()[j]; k < a.outerIndexPtr()[j + 1]; ++k) {
      const double* x_row = x_rows.data() + static_cast<Eigen::Index>(a.innerIndexPtr()[k]) * columns;
      sum.noalias() += a.valuePtr()[k] * Eigen::Map<const Row>(x_row, columns);
    }
    r.row(j) = b.row(j) - sum;
  }
}

/// b - a x for a symmetric a stored whole, in parallel over the rows; one pass over a for all
/// columns of x.
Eigen::MatrixXd symmetric_residual(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd& x) {
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajorMatrix x_rows = x;  // a row's columns next to each other for the gather
  RowMajorMatrix r(b.rows(), b.cols());
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.outerSize(), 1024), [&](const tbb::blocked_range<Eigen::Index>& rows) {
    switch (x.cols()) {
      case 1: symmetric_residual_rows<1>(a, b, x_rows, rows.begin(), rows.end(), r); break;
      case 3: symmetric_residual_rows<3>(a, b, x_rows, rows.begin(), rows.end(), r); break;
      case 6: symmetric_residual_rows<6>(a, b, x_rows, rows.begin(), rows.end(), r); break;
      default: symmetric_residual_rows<Eigen::Dynamic>(a, b, x_rows, rows.begin(), rows.end(), r); break;
    }
  });
  return r;
}

/// g w in parallel over blocks of g's rows (g tall: n x G's columns, w a few columns).
Eigen::MatrixXd multiply_by_rows(const Eigen::MatrixXd& g, const Eigen::MatrixXd& w) {
  Eigen::MatrixXd out(g.rows(), w.cols());
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, g.rows(), 2048), [&](const tbb::blocked_range<Eigen::Index>& rows) {
    const auto count = static_cast<Eigen::Index>(rows.size());
    out.middleRows(rows.begin(), count).noalias() = g.middleRows(rows.begin(), count) * w;
  });
  return out;
}

/// Iterative refinement of a x = b with `solve` (an approximate inverse of a): true as soon as the
/// backward error of x is at most `tolerance`; false after `steps` corrections without that, or
/// when x is not finite.
template <typename Solve>
bool refine(const Eigen::SparseMatrix<double>& a, double a_norm, const Eigen::MatrixXd& b, Eigen::MatrixXd& x,
            double tolerance, int steps, const Solve& solve) {
  for (int step = 0;; ++step) {
    if (!x.allFinite()) return false;
    const Eigen::MatrixXd r = symmetric_residual(a, b, x);
    if (backward_error(a_norm, r, x, b) <= tolerance) return true;
    if (step == steps) return false;
    x += solve(r);
  }
}

/// Eigen's CHOLMOD wrapper with its factor readable (for the parallel substitution).
class CholmodLlt : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> {
 public:
  const cholmod_factor* factor() const { return m_cholmodFactor; }
};

/// Before the sparse update has been measured, one of its changed rows is taken to cost this
/// share of a full solve of one column (measured: 1/9 for a stroke of the abdomen at 45k cells).
constexpr double kSparseRowShareOfSolve = 0.25;

/// The sparse update's first forward substitution visits only the supernodes above b's rows while
/// b is non-zero on at most this share of them (the design's targets sit on the constrained cells).
constexpr double kSparseRightHandSideShare = 0.25;

/// The sparse update replaces new columns of G only when those would cost this many times more:
/// columns are kept and answer every later edit on their rows without a solve (a control point
/// placed, moved and typed at), the sparse update is paid again at every edit.
constexpr double kSparseAdvantage = 2.0;

/// Solutions kept for systems that come back (an undo and a redo, a drag back and forth).
constexpr std::size_t kRememberedSolutions = 2;

/// A system solved with the factor, as RecentResults keys it: its diagonal (the off-diagonal
/// entries are the factorized ones) and right-hand side. A SystemProbe compares the caller's
/// arrays with it without copying them.
struct SystemProbe {
  const Eigen::VectorXd& diagonal;
  const Eigen::MatrixXd& b;
};
struct SolvedSystem {
  Eigen::VectorXd diagonal;
  Eigen::MatrixXd b;
  bool operator==(const SystemProbe& p) const {
    return b.rows() == p.b.rows() && b.cols() == p.b.cols() && diagonal.size() == p.diagonal.size() && diagonal == p.diagonal && b == p.b;
  }
  bool operator==(const SolvedSystem& other) const { return *this == SystemProbe{other.diagonal, other.b}; }
};

/// Right-hand sides up to this many columns are substituted on all cores (SupernodalSubstitution);
/// wider blocks go to CHOLMOD's solve, whose BLAS-3 kernels already use them.
constexpr Eigen::Index kParallelSubstitutionColumns = 8;

}  // namespace

struct SparseCholesky::Impl {
  CholmodLlt llt;
  std::optional<SupernodalSubstitution> substitution;  ///< schedule of the current analysis
  std::vector<int> outer;
  std::vector<int> inner;
  bool analyzed = false;
  std::vector<float> single_values;  ///< the factor's values in float (solve_single_precision), made on first use
  std::vector<double> values;     ///< the factorized matrix's values (pattern: outer, inner)
  double factor_seconds = 0;      ///< wall time of the last numeric factorization
  double solve_seconds = 0;       ///< wall time of one solve with the factor (one column), last measured
  Eigen::VectorXd diagonal;       ///< the factorized matrix's diagonal
  double column_seconds = 0;      ///< wall time per column of the last batch of Woodbury columns (0: none yet)
  // Woodbury update: column c of low_rank_columns is a0^-1 e_r for r = low_rank_row[c] (a0 the
  // factorized matrix); column_of_row[r] is c or -1. Emptied by every factorization.
  Eigen::MatrixXd low_rank_columns;
  std::vector<Eigen::Index> low_rank_row;
  std::vector<Eigen::Index> column_of_row;
  // Sparse update (UpdatePolicy::sparse): W = L^-1 P E of every row an edit has changed since
  // the factorization, kept in batches on the rows they reach, and W^T W where edits needed it.
  // Emptied by every factorization and past kMaxLowRankRows columns or kMaxLowRankBytes.
  ForwardColumnBatches sparse_columns{static_cast<std::size_t>(SparseCholesky::kMaxLowRankRows), SparseCholesky::kMaxLowRankBytes};
  double sparse_row_seconds = 0;    ///< per changed row, for its column of W (0: not measured yet)
  double sparse_apply_seconds = 0;  ///< per right-hand side column: the first application of the update
  // The last kRememberedSolutions systems solved with this factor (their diagonal and b: the
  // off-diagonal entries are the factorized ones) and their solutions, newest first.
  RecentResults<SolvedSystem, Eigen::MatrixXd> remembered{kRememberedSolutions};

  void remember(Eigen::VectorXd a_diagonal, const Eigen::MatrixXd& b, const Eigen::MatrixXd& x) {
    remembered.remember(SolvedSystem{std::move(a_diagonal), b}, x);
  }

  bool same_pattern(const Eigen::SparseMatrix<double>& a) const {
    if (!analyzed || static_cast<std::size_t>(a.outerSize() + 1) != outer.size()) return false;
    if (!std::equal(outer.begin(), outer.end(), a.outerIndexPtr())) return false;
    return static_cast<std::size_t>(outer.back()) == inner.size() && std::equal(inner.begin(), inner.end(), a.innerIndexPtr());
  }
  /// Whether `a` (of the same pattern) has the factorized matrix's values.
  bool same_values(const Eigen::SparseMatrix<double>& a) const {
    return values.size() == static_cast<std::size_t>(a.nonZeros()) && std::equal(values.begin(), values.end(), a.valuePtr());
  }
  /// a0^-1 b with the factor (not checked for finiteness).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const {
    if (!substitution || b.cols() > kParallelSubstitutionColumns) return llt.solve(b);
    Eigen::MatrixXd x = b;
    substitution->solve(*llt.factor(), x);
    return x;
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::factorize(const Eigen::SparseMatrix<double>& a) {
  if (!a.isCompressed()) throw ComputeError("sparse Cholesky needs a compressed matrix");
  if (impl_->same_pattern(a)) {
    ++reused_;
  } else {
    impl_->substitution.reset();
    impl_->llt.analyzePattern(a);
    impl_->outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1);
    impl_->inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + impl_->outer.back());
    impl_->analyzed = true;
  }
  const Clock::time_point start = Clock::now();
  impl_->llt.factorize(a);
  if (impl_->llt.info() != Eigen::Success) {
    impl_->analyzed = false;
    impl_->values.clear();
    throw ComputeError("sparse Cholesky factorization failed: the design system is not positive definite");
  }
  impl_->factor_seconds = seconds_between(start, Clock::now());
  if (!impl_->substitution) impl_->substitution.emplace(*impl_->llt.factor());
  impl_->values.assign(a.valuePtr(), a.valuePtr() + a.nonZeros());
  impl_->single_values.clear();
  impl_->diagonal = a.diagonal();
  impl_->low_rank_columns.resize(0, 0);
  impl_->low_rank_row.clear();
  impl_->column_of_row.assign(static_cast<std::size_t>(a.rows()), -1);
  impl_->sparse_columns.clear();
  impl_->remembered.clear();
}

Eigen::Index SparseCholesky::low_rank_rows() const { return static_cast<Eigen::Index>(impl_->low_rank_row.size()); }

bool SparseCholesky::factor_is_of(const Eigen::SparseMatrix<double>& a) const {
  return impl_->same_pattern(a) && impl_->same_values(a);
}

Eigen::MatrixXd SparseCholesky::solve_refined(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b) const {
  Eigen::MatrixXd x = solve(b);
  for (int step = 0; step < kRefinementSteps; ++step) {
    const Eigen::MatrixXd r = b - a * x;
    x += solve(r);
  }
  return x;
}

bool SparseCholesky::solve_with_current_factor(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b,
                                               Eigen::MatrixXd& x, double relative_tolerance, int max_iterations) const {
  last_iterations_ = 0;
  last_factor_solves_ = 0;
  if (!impl_->analyzed || !impl_->same_pattern(a) || x.rows() != b.rows() || x.cols() != b.cols()) return false;
  // Giving up costs a factorization and a refined solve of every column.
  const double refactor_seconds =
      impl_->factor_seconds + static_cast<double>(b.cols()) * (kRefinementSteps + 1) * impl_->solve_seconds;
  if (impl_->same_values(a)) {  // only the right-hand side changed: the factor is exact
    const Eigen::VectorXd a_diagonal = a.diagonal();
    if (recall(a_diagonal, b, x)) return true;
    // Without a solve when G has a column for every row where b is not zero (a value typed at a
    // control point the last edits placed); otherwise refined as solve_refined does, but only
    // until the tolerance is met (usually one step).
    if (!(low_rank_rows() > 0 && solve_diagonal_update(a, b, x, relative_tolerance, refactor_seconds, false))) {
      x = solve(b);
      ++last_factor_solves_;
      refine(a, norm_1(a), b, x, relative_tolerance, kRefinementSteps, [&](const Eigen::MatrixXd& r) {
        ++last_factor_solves_;
        return solve(r);
      });
    }
    impl_->remember(a_diagonal, b, x);
    return true;
  }
  // A change of d diagonal entries only (constraints added or removed) is a rank-d update: CG with
  // the old factor converges in about d + 1 iterations per column, with a residual that need not
  // fall before. Refactorize at once when those iterations cost more than a new factor.
  int changed = 0;
  bool diagonal_only = true;
  for (Eigen::Index j = 0; j < a.outerSize(); ++j)
    for (int k = a.outerIndexPtr()[j]; k < a.outerIndexPtr()[j + 1]; ++k)
      if (a.valuePtr()[k] != impl_->values[static_cast<std::size_t>(k)]) {
        ++changed;
        diagonal_only = diagonal_only && a.innerIndexPtr()[k] == j;
      }
  if (diagonal_only) {
    Eigen::VectorXd a_diagonal = a.diagonal();
    if (recall(a_diagonal, b, x)) return true;
    const Eigen::MatrixXd start = x;
    if (solve_diagonal_update(a, b, x, relative_tolerance, refactor_seconds, true)) {
      impl_->remember(std::move(a_diagonal), b, x);
      return true;
    }
    x = start;
  }
  Eigen::Index columns = 0;
  for (Eigen::Index col = 0; col < b.cols(); ++col) columns += b.col(col).squaredNorm() > 0.0 ? 1 : 0;
  if (diagonal_only && static_cast<double>(columns) * (changed + 1) * impl_->solve_seconds > refactor_seconds) return false;
  const int first_projected_iteration = diagonal_only ? std::max(kFirstProjectedIteration, changed + 2) : kFirstProjectedIteration;
  const Clock::time_point start = Clock::now();
  for (Eigen::Index col = 0; col < b.cols(); ++col) {
    const double b_norm = b.col(col).norm();
    if (b_norm == 0.0) {
      x.col(col).setZero();
      continue;
    }
    Eigen::VectorXd xc = x.col(col);
    Eigen::VectorXd r = b.col(col) - a * xc;
    const double r0_norm = r.norm();
    if (r0_norm <= relative_tolerance * b_norm) continue;
    Eigen::VectorXd z = impl_->solve(r);
    ++last_factor_solves_;
    Eigen::VectorXd p = z;
    double rz = r.dot(z);
    bool converged = false;
    for (int it = 0; it < max_iterations && !converged; ++it) {
      const Eigen::VectorXd ap = a * p;
      const double curvature = p.dot(ap);
      if (!(curvature > 0.0) || !(rz > 0.0)) return false;
      const double alpha = rz / curvature;
      xc += alpha * p;
      r -= alpha * ap;
      ++last_iterations_;
      const double r_norm = r.norm();
      converged = r_norm <= relative_tolerance * b_norm;
      if (converged) break;
      if (it + 1 >= first_projected_iteration) {
        // Off track (a stroke edit of a line field changes hundreds of rows: CG stalls near 1e-5),
        // or on track but dearer than a new factor (the coupled system after a frame change):
        // give up so that the caller's factorization is not preceded by wasted solves.
        const double rate = std::pow(r_norm / r0_norm, 1.0 / (it + 1));
        const double remaining = rate < 1.0 ? std::log(relative_tolerance * b_norm / r_norm) / std::log(rate)
                                            : std::numeric_limits<double>::infinity();
        const double seconds_per_iteration = seconds_between(start, Clock::now()) / last_iterations_;
        if (it + 1 + remaining > max_iterations || remaining * seconds_per_iteration > refactor_seconds) return false;
      }
      z = impl_->solve(r);
      ++last_factor_solves_;
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
    }
    if (!converged || !xc.allFinite()) return false;
    if ((b.col(col) - a * xc).norm() > 10.0 * relative_tolerance * b_norm) return false;  // recurrence drifted
    x.col(col) = xc;
  }
  return true;
}

bool SparseCholesky::solve_diagonal_update(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, Eigen::MatrixXd& x,
                                           double relative_tolerance, double refactor_seconds, bool new_columns_allowed) const {
  Impl& impl = *impl_;
  const Eigen::Index n = a.rows();
  const Eigen::VectorXd diagonal = a.diagonal();
  const Eigen::VectorXd change = diagonal - impl.diagonal;  // a = a0 + diag(change)
  const auto has_column = [&](Eigen::Index r) { return impl.column_of_row[static_cast<std::size_t>(r)] >= 0; };
  std::vector<Eigen::Index> changed;          // rows of E: diagonal entries that differ from a0's
  std::vector<Eigen::Index> missing_changed;  // ... without a column of G yet
  std::vector<Eigen::Index> missing_support;  // other rows where b is not zero, without a column
  for (Eigen::Index r = 0; r < n; ++r) {
    if (change[r] != 0.0) {
      changed.push_back(r);
      if (!has_column(r)) missing_changed.push_back(r);
    } else if (!has_column(r) && (b.row(r).array() != 0.0).any()) {
      missing_support.push_back(r);
    }
  }
  const auto kept = static_cast<Eigen::Index>(impl.low_rank_row.size());
  // The new columns cost about their count times one column's solve (measured on the last batch
  // of columns, or on the last solve): at most kColumnBudget new factors, and G stays within its
  // bounds.
  const double column_seconds = impl.column_seconds > 0 ? impl.column_seconds : impl.solve_seconds;
  const auto affordable = [&](std::size_t count) {
    const Eigen::Index rows = kept + static_cast<Eigen::Index>(count);
    return rows <= kMaxLowRankRows && 8.0 * static_cast<double>(n) * static_cast<double>(rows) <= kMaxLowRankBytes &&
           static_cast<double>(count) * column_seconds <= kColumnBudget * refactor_seconds;
  };
  const std::size_t support_columns = missing_changed.size() + missing_support.size();
  // Changed rows without columns (a stroke drawn or dragged over fresh cells): their columns cost
  // a full solve each, the sparse update only the part of the factor above them.
  const bool sparse_possible = new_columns_allowed && impl.substitution.has_value() && !changed.empty() &&
                               static_cast<Eigen::Index>(changed.size()) <= kMaxLowRankRows &&
                               8.0 * static_cast<double>(n) * static_cast<double>(changed.size()) <= kMaxLowRankBytes;
  if (sparse_possible && policy_ != UpdatePolicy::columns && (policy_ == UpdatePolicy::sparse || !missing_changed.empty())) {
    const double sparse_seconds = sparse_update_seconds(impl.sparse_columns.rows_to_make(changed).size(), b.cols());
    const double column_path_seconds =
        static_cast<double>(support_columns) * column_seconds + static_cast<double>(b.cols()) * impl.solve_seconds;
    if (policy_ == UpdatePolicy::sparse ||
        (sparse_seconds <= refactor_seconds &&
         (kSparseAdvantage * sparse_seconds < column_path_seconds || !affordable(missing_changed.size()))))
      return solve_sparse_update(a, b, x, relative_tolerance, changed, change);
  }
  // y = a0^-1 b from G's columns of the rows where b is not zero (no solve), when they exist or can
  // be afforded; otherwise from a solve with the factor. The right-hand side's extra columns are
  // bought at once only while cheap (one refactorization); dearer, only by an edit whose changed
  // rows all have columns already (a stroke moved back, undo, redo): an edit to fresh cells (a drag)
  // pays for its changed rows only, so that G does not fill with columns a drag never reuses.
  const double all_columns_seconds = static_cast<double>(support_columns) * column_seconds;
  const bool y_from_columns =
      support_columns == 0 || (new_columns_allowed && affordable(support_columns) &&
                               (missing_changed.empty() || all_columns_seconds <= refactor_seconds));
  if (!y_from_columns && (!new_columns_allowed || changed.empty() || !affordable(missing_changed.size()))) return false;
  std::vector<Eigen::Index> missing = missing_changed;
  if (y_from_columns) missing.insert(missing.end(), missing_support.begin(), missing_support.end());
  const auto new_columns = static_cast<Eigen::Index>(missing.size());
  const Eigen::Index rhs_columns = y_from_columns ? 0 : b.cols();
  Eigen::MatrixXd y;
  if (new_columns + rhs_columns > 0) {
    // The new columns and (when needed) y in one solve: the factor is read once for all of them.
    const Clock::time_point start = Clock::now();
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, new_columns + rhs_columns);
    for (Eigen::Index c = 0; c < new_columns; ++c) rhs(missing[static_cast<std::size_t>(c)], c) = 1.0;
    if (rhs_columns > 0) rhs.rightCols(rhs_columns) = b;
    Eigen::MatrixXd solved = impl.solve(rhs);
    ++last_factor_solves_;
    if (impl.llt.info() != Eigen::Success || !solved.allFinite()) return false;
    if (new_columns > 0) {
      impl.low_rank_columns.conservativeResize(n, kept + new_columns);
      impl.low_rank_columns.rightCols(new_columns) = solved.leftCols(new_columns);
      for (std::size_t c = 0; c < missing.size(); ++c) {
        impl.column_of_row[static_cast<std::size_t>(missing[c])] = kept + static_cast<Eigen::Index>(c);
        impl.low_rank_row.push_back(missing[c]);
      }
    }
    impl.column_seconds = seconds_between(start, Clock::now()) / static_cast<double>(rhs.cols());
    if (rhs_columns > 0) y = solved.rightCols(rhs_columns);
  }
  const Eigen::MatrixXd& g = impl.low_rank_columns;
  const auto column_of = [&](Eigen::Index r) { return impl.column_of_row[static_cast<std::size_t>(r)]; };
  // a = a0 + E D E^T over the changed rows: with W the coefficients of r on G's rows,
  //   a^-1 r = a0^-1 r - G_E (I + D E^T G_E)^-1 D E^T a0^-1 r,   a0^-1 r = G W (r zero elsewhere).
  const auto rank = static_cast<Eigen::Index>(changed.size());
  Eigen::MatrixXd g_at_changed(rank, g.cols());  // E^T G
  for (Eigen::Index k = 0; k < rank; ++k) g_at_changed.row(k) = g.row(changed[static_cast<std::size_t>(k)]);
  Eigen::MatrixXd capacitance = Eigen::MatrixXd::Identity(rank, rank);  // I + D E^T G_E
  for (Eigen::Index c = 0; c < rank; ++c) {
    const Eigen::Index column = column_of(changed[static_cast<std::size_t>(c)]);
    for (Eigen::Index k = 0; k < rank; ++k) capacitance(k, c) += change[changed[static_cast<std::size_t>(k)]] * g_at_changed(k, column);
  }
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(capacitance);
  // Subtracts (I + D E^T G_E)^-1 D (E^T a0^-1 r) from the changed rows' coefficients in w.
  const auto correct_coefficients = [&](Eigen::MatrixXd& w, const Eigen::MatrixXd& a0_inverse_r_at_changed) {
    if (rank == 0) return;
    const Eigen::MatrixXd z = lu.solve(change(changed).asDiagonal() * a0_inverse_r_at_changed);
    for (Eigen::Index k = 0; k < rank; ++k) w.row(column_of(changed[static_cast<std::size_t>(k)])) -= z.row(k);
  };
  const auto coefficients_on_rows = [&](const Eigen::MatrixXd& r) {  // W: r on G's rows, zero elsewhere
    Eigen::MatrixXd w(g.cols(), r.cols());
    for (std::size_t c = 0; c < impl.low_rank_row.size(); ++c) w.row(static_cast<Eigen::Index>(c)) = r.row(impl.low_rank_row[c]);
    return w;
  };
  // a^-1 r from G alone, for r zero outside G's rows: G (W - Z), one product with G.
  const auto solve_by_columns = [&](const Eigen::MatrixXd& r) {
    Eigen::MatrixXd w = coefficients_on_rows(r);
    correct_coefficients(w, g_at_changed * w);
    return multiply_by_rows(g, w);
  };
  // a^-1 r from y = a0^-1 r (a solve with the factor): y - G Z.
  const auto update_solved = [&](Eigen::MatrixXd& solved) {
    if (rank == 0) return;
    Eigen::MatrixXd w = Eigen::MatrixXd::Zero(g.cols(), solved.cols());
    correct_coefficients(w, solved(changed, Eigen::all));
    solved += multiply_by_rows(g, w);
  };
  if (y_from_columns) {
    x = solve_by_columns(b);
  } else {
    update_solved(y);
    x = std::move(y);
  }
  // The result's error is mostly on the changed rows (the capacitance system's rounding, amplified
  // by its condition), so its residual lives there too and G's columns correct it without a solve
  // while each correction gains a factor kColumnRefinementGain; a residual that stays elsewhere is
  // refined with solves with the factor (at most kLowRankRefinementSteps of each kind).
  const double a_norm = norm_1(a);
  double last_error = std::numeric_limits<double>::infinity();
  bool by_columns = true;
  int steps = 0;
  bool converged = false;
  while (x.allFinite()) {
    const Eigen::MatrixXd r = symmetric_residual(a, b, x);
    const double error = backward_error(a_norm, r, x, b);
    if (error <= relative_tolerance) {
      converged = true;
      break;
    }
    if (by_columns && (error > last_error / kColumnRefinementGain || steps == kLowRankRefinementSteps)) {
      by_columns = false;
      steps = 0;
    }
    if (!by_columns && steps == kLowRankRefinementSteps) break;
    last_error = error;
    ++steps;
    if (by_columns) {
      x += solve_by_columns(r);
    } else {
      ++last_factor_solves_;
      Eigen::MatrixXd solved = impl.solve(r);
      update_solved(solved);
      x += solved;
    }
  }
  if (converged) ++low_rank_solves_;
  return converged;
}

bool SparseCholesky::recall(const Eigen::VectorXd& a_diagonal, const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const {
  const Eigen::MatrixXd* known = impl_->remembered.find(SystemProbe{a_diagonal, b});
  if (known == nullptr) return false;
  x = *known;
  ++remembered_solves_;
  return true;
}

double SparseCholesky::sparse_update_seconds(std::size_t rows, Eigen::Index columns) const {
  const Impl& impl = *impl_;
  const double row_seconds = impl.sparse_row_seconds > 0 ? impl.sparse_row_seconds : kSparseRowShareOfSolve * impl.solve_seconds;
  const double apply_seconds = impl.sparse_apply_seconds > 0 ? impl.sparse_apply_seconds : impl.solve_seconds;
  // W for the new rows, then twice the measured application to b (with its residual correction;
  // a refinement solve is rare). The weight 2 tunes the choice against buying columns: at 1 the
  // control points' edits take the sparse update, pay it again at every edit, and the bench's
  // value_point edit went from 5 to 18-23 ms at 45k cells.
  return static_cast<double>(rows) * row_seconds + 2.0 * static_cast<double>(columns) * apply_seconds;
}

bool SparseCholesky::solve_sparse_update(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, Eigen::MatrixXd& x,
                                         double relative_tolerance, const std::vector<Eigen::Index>& changed,
                                         const Eigen::VectorXd& change) const {
  Impl& impl = *impl_;
  const cholmod_factor& factor = *impl.llt.factor();
  const SupernodalSubstitution& substitution = *impl.substitution;
  const Clock::time_point start_columns = Clock::now();
  const int made = impl.sparse_columns.make(substitution, factor, changed);
  if (made < 0) return false;
  if (made > 0) {
    impl.sparse_row_seconds = seconds_between(start_columns, Clock::now()) / static_cast<double>(made);
    sparse_columns_made_ += made;
  }
  // This edit's columns of W and their products.
  const auto rank = static_cast<Eigen::Index>(changed.size());
  const ForwardColumnBatches::Selection w = impl.sparse_columns.select(changed);
  const Eigen::VectorXd d = change(changed);
  // a = a0 + E D E^T: a^-1 r = P^T L^-T (y - W Z), y = L^-1 P r, Z = (I + D W^T W)^-1 D W^T y.
  Eigen::MatrixXd capacitance = d.asDiagonal() * w.gram();
  capacitance.diagonal().array() += 1.0;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(capacitance);
  // y - W Z on W's rows, for y = L^-1 P r.
  const auto update = [&](Eigen::MatrixXd& y) { w.subtract_times(y, lu.solve(d.asDiagonal() * w.transpose_times(y))); };
  const auto solve_updated = [&](const Eigen::MatrixXd& r) {
    ++last_factor_solves_;
    Eigen::MatrixXd y = substitution.forward_of(factor, r);
    update(y);
    return substitution.backward_of(factor, std::move(y));
  };
  const Clock::time_point start = Clock::now();
  // b lives on the constrained cells: its forward substitution reaches only the supernodes above them.
  std::vector<Eigen::Index> support;
  for (Eigen::Index r = 0; r < b.rows(); ++r)
    if ((b.row(r).array() != 0.0).any()) support.push_back(r);
  ++last_factor_solves_;
  Eigen::MatrixXd y;
  if (static_cast<double>(support.size()) <= kSparseRightHandSideShare * static_cast<double>(b.rows())) {
    std::vector<Eigen::Index> reached_by_b;
    const Eigen::MatrixXd y_reached = substitution.forward_sparse(factor, support, b(support, Eigen::all), reached_by_b);
    y = Eigen::MatrixXd::Zero(b.rows(), b.cols());
    y(reached_by_b, Eigen::all) = y_reached;
  } else {
    y = substitution.forward_of(factor, b);
  }
  update(y);
  // The rounding of the update leaves its residual on the changed rows (measured: all but 1e-6 of
  // its square there): r_C = b_C - a(C, :) x needs x only on the changed rows' neighbours, a back
  // substitution over the supernodes above them, and a^-1 E r_C = P^T L^-T W (I + D W^T W)^-1 r_C
  // corrects y before the one whole back substitution. What is left is refined as usual.
  std::vector<Eigen::Index> neighbours;
  for (const Eigen::Index c : changed)
    for (int k = a.outerIndexPtr()[c]; k < a.outerIndexPtr()[c + 1]; ++k) neighbours.push_back(a.innerIndexPtr()[k]);
  std::sort(neighbours.begin(), neighbours.end());
  neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
  const Eigen::MatrixXd x_near = substitution.backward_rows(factor, y, neighbours);
  Eigen::MatrixXd r_changed(rank, b.cols());
  for (Eigen::Index i = 0; i < rank; ++i) {
    const Eigen::Index c = changed[static_cast<std::size_t>(i)];
    r_changed.row(i) = b.row(c);
    for (int k = a.outerIndexPtr()[c]; k < a.outerIndexPtr()[c + 1]; ++k) {
      const auto at = std::lower_bound(neighbours.begin(), neighbours.end(), static_cast<Eigen::Index>(a.innerIndexPtr()[k]));
      r_changed.row(i) -= a.valuePtr()[k] * x_near.row(at - neighbours.begin());
    }
  }
  w.subtract_times(y, -lu.solve(r_changed));
  x = substitution.backward_of(factor, std::move(y));
  if (b.cols() > 0) impl.sparse_apply_seconds = seconds_between(start, Clock::now()) / static_cast<double>(b.cols());
  if (rank == 0 || !x.allFinite()) return false;
  const bool converged = refine(a, norm_1(a), b, x, relative_tolerance, kLowRankRefinementSteps, solve_updated);
  if (converged) {
    ++low_rank_solves_;
    ++sparse_update_solves_;
  }
  return converged;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& b) const {
  const Clock::time_point start = Clock::now();
  Eigen::MatrixXd x = impl_->solve(b);
  if (b.cols() > 0) impl_->solve_seconds = seconds_between(start, Clock::now()) / static_cast<double>(b.cols());
  if (impl_->llt.info() != Eigen::Success || !x.allFinite())
    throw ComputeError("sparse Cholesky solve failed or produced a non-finite value");
  return x;
}

Eigen::VectorXd SparseCholesky::solve_single_precision(const Eigen::VectorXd& b) const {
  if (!impl_->substitution) return solve(b);
  if (impl_->single_values.empty()) impl_->single_values = impl_->substitution->single_precision_values(*impl_->llt.factor());
  Eigen::VectorXd x = b;
  impl_->substitution->solve_single(*impl_->llt.factor(), impl_->single_values, x);
  if (!x.allFinite()) throw ComputeError("sparse Cholesky solve in single precision produced a non-finite value");
  return x;
}

}  // namespace cleave
