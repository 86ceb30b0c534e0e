// GCC 12 reports -Wnull-dereference inside Eigen (sparse Ref construction, vector dot products)
// after inlining: a false positive for possibly-empty vectors. Silenced for this file's headers.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "cleave/stress/sparse_cholesky.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

/// CG with the kept factor projects its remaining work from this iteration on at the earliest.
constexpr int kFirstProjectedIteration = 4;

/// Iterative refinement of a x = b with `solve` (an approximate inverse of a): true as soon as every
/// column has ||b - a x|| <= relative_tolerance ||b||; false after `steps` corrections without that,
/// or when x is not finite.
template <typename Solve>
bool refine(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b, Eigen::MatrixXd& x, double relative_tolerance,
            int steps, const Solve& solve) {
  const Eigen::VectorXd b_norm = b.colwise().norm().transpose();
  for (int step = 0;; ++step) {
    if (!x.allFinite()) return false;
    const Eigen::MatrixXd r = b - a * x;
    bool converged = true;
    for (Eigen::Index col = 0; col < b.cols() && converged; ++col) converged = r.col(col).norm() <= relative_tolerance * b_norm[col];
    if (converged) return true;
    if (step == steps) return false;
    x += solve(r);
  }
}

}  // namespace

struct SparseCholesky::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  std::vector<int> outer;
  std::vector<int> inner;
  bool analyzed = false;
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

  bool same_pattern(const Eigen::SparseMatrix<double>& a) const {
    if (!analyzed || static_cast<std::size_t>(a.outerSize() + 1) != outer.size()) return false;
    for (std::size_t i = 0; i < outer.size(); ++i)
      if (outer[i] != a.outerIndexPtr()[i]) return false;
    if (static_cast<std::size_t>(outer.back()) != inner.size()) return false;
    for (std::size_t i = 0; i < inner.size(); ++i)
      if (inner[i] != a.innerIndexPtr()[i]) return false;
    return true;
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
  impl_->values.assign(a.valuePtr(), a.valuePtr() + a.nonZeros());
  impl_->diagonal = a.diagonal();
  impl_->low_rank_columns.resize(0, 0);
  impl_->low_rank_row.clear();
  impl_->column_of_row.assign(static_cast<std::size_t>(a.rows()), -1);
}

Eigen::Index SparseCholesky::low_rank_rows() const { return static_cast<Eigen::Index>(impl_->low_rank_row.size()); }

bool SparseCholesky::factor_is_of(const Eigen::SparseMatrix<double>& a) const {
  if (!impl_->same_pattern(a) || impl_->values.size() != static_cast<std::size_t>(a.nonZeros())) return false;
  for (std::size_t i = 0; i < impl_->values.size(); ++i)
    if (impl_->values[i] != a.valuePtr()[i]) return false;
  return true;
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
  if (!impl_->analyzed || !impl_->same_pattern(a) || x.rows() != b.rows() || x.cols() != b.cols()) return false;
  if (factor_is_of(a)) {  // only the right-hand side changed: the factor is exact
    // Refined as solve_refined does, but only until the tolerance is met (usually one step).
    x = solve(b);
    refine(a, b, x, relative_tolerance, kRefinementSteps, [&](const Eigen::MatrixXd& r) { return solve(r); });
    return true;
  }
  // Giving up costs a factorization and a refined solve of every column.
  const double refactor_seconds =
      impl_->factor_seconds + static_cast<double>(b.cols()) * (kRefinementSteps + 1) * impl_->solve_seconds;
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
    const Eigen::MatrixXd start = x;
    if (solve_diagonal_update(a, b, x, relative_tolerance, refactor_seconds)) return true;
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
    Eigen::VectorXd z = impl_->llt.solve(r);
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
      z = impl_->llt.solve(r);
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
                                           double relative_tolerance, double refactor_seconds) const {
  Impl& impl = *impl_;
  const Eigen::Index n = a.rows();
  const Eigen::VectorXd diagonal = a.diagonal();
  std::vector<Eigen::Index> missing;  // changed rows without a column of G yet
  for (Eigen::Index r = 0; r < n; ++r)
    if (diagonal[r] != impl.diagonal[r] && impl.column_of_row[static_cast<std::size_t>(r)] < 0) missing.push_back(r);
  const auto kept = static_cast<Eigen::Index>(impl.low_rank_row.size());
  const Eigen::Index rows = kept + static_cast<Eigen::Index>(missing.size());
  if (rows == 0 || rows > kMaxLowRankRows || 8.0 * static_cast<double>(n) * static_cast<double>(rows) > kMaxLowRankBytes)
    return false;
  // The new columns cost about their count times one column's solve (measured on the last batch
  // of columns, or on the last solve): not more than a new factor.
  const double column_seconds = impl.column_seconds > 0 ? impl.column_seconds : impl.solve_seconds;
  if (static_cast<double>(missing.size()) * column_seconds > refactor_seconds) return false;
  // y = a0^-1 b and the new columns in one solve (the factor is read once for all of them).
  const auto new_columns = static_cast<Eigen::Index>(missing.size());
  Eigen::MatrixXd y;
  if (new_columns > 0) {
    const Clock::time_point start = Clock::now();
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, new_columns + b.cols());
    for (Eigen::Index c = 0; c < new_columns; ++c) rhs(missing[static_cast<std::size_t>(c)], c) = 1.0;
    rhs.rightCols(b.cols()) = b;
    const Eigen::MatrixXd solved = impl.llt.solve(rhs);
    if (impl.llt.info() != Eigen::Success || !solved.allFinite()) return false;
    impl.column_seconds = seconds_between(start, Clock::now()) / static_cast<double>(rhs.cols());
    impl.low_rank_columns.conservativeResize(n, rows);
    impl.low_rank_columns.rightCols(new_columns) = solved.leftCols(new_columns);
    y = solved.rightCols(b.cols());
    for (std::size_t c = 0; c < missing.size(); ++c) {
      impl.column_of_row[static_cast<std::size_t>(missing[c])] = kept + static_cast<Eigen::Index>(c);
      impl.low_rank_row.push_back(missing[c]);
    }
  }
  // a = a0 + E D E^T over every kept row (D = 0 where a row has its factorized value again).
  const Eigen::MatrixXd& g = impl.low_rank_columns;
  Eigen::VectorXd d(rows);
  for (Eigen::Index c = 0; c < rows; ++c) {
    const Eigen::Index r = impl.low_rank_row[static_cast<std::size_t>(c)];
    d[c] = diagonal[r] - impl.diagonal[r];
  }
  Eigen::MatrixXd capacitance = Eigen::MatrixXd::Identity(rows, rows);  // I + D E^T G
  for (Eigen::Index c = 0; c < rows; ++c)
    for (Eigen::Index k = 0; k < rows; ++k) capacitance(k, c) += d[k] * g(impl.low_rank_row[static_cast<std::size_t>(k)], c);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(capacitance);
  // a^-1 r from y = a0^-1 r.
  const auto update = [&](Eigen::MatrixXd& solved) {
    Eigen::MatrixXd t(rows, solved.cols());
    for (Eigen::Index k = 0; k < rows; ++k) t.row(k) = d[k] * solved.row(impl.low_rank_row[static_cast<std::size_t>(k)]);
    solved.noalias() -= g * lu.solve(t);
  };
  if (y.size() == 0) y = impl.llt.solve(b);
  update(y);
  x = std::move(y);
  const bool converged = refine(a, b, x, relative_tolerance, kLowRankRefinementSteps, [&](const Eigen::MatrixXd& r) {
    Eigen::MatrixXd solved = impl.llt.solve(r);
    update(solved);
    return solved;
  });
  if (converged) ++low_rank_solves_;
  return converged;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& b) const {
  const Clock::time_point start = Clock::now();
  Eigen::MatrixXd x = impl_->llt.solve(b);
  if (b.cols() > 0) impl_->solve_seconds = seconds_between(start, Clock::now()) / static_cast<double>(b.cols());
  if (impl_->llt.info() != Eigen::Success || !x.allFinite())
    throw ComputeError("sparse Cholesky solve failed or produced a non-finite value");
  return x;
}

}  // namespace cleave
