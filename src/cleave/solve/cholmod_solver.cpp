#include "cleave/solve/cholmod_solver.hpp"

#include <cholmod.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <optional>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/solve/sparse_multiply.hpp"
#include "cleave/solve/supernodal_substitution.hpp"

namespace cleave {
namespace {

/// Substitutions with the single-precision factor before the double one takes over: one refinement
/// takes the incised 44k tube from a residual of 1.2e-5 to 2.5e-11 to 7.6e-11 (session 28).
constexpr int kMaxSingleSubstitutions = 3;

/// The first single-precision substitution leaves out b's smallest entries while their norm
/// stays below this share of the tolerance times ||b||: its forward sweep then visits only the
/// supernodes above the rest. The residual is checked against the whole b (and refined if need be).
constexpr double kDroppedShareOfTolerance = 1e-2;
/// A support of more than this share of the rows is solved whole (it would reach most supernodes).
constexpr double kSupportedShare = 0.5;

/// The rows of b left when its smallest entries are left out while their norm stays at most
/// `dropped_norm` (by binary exponent: every entry below 2^k, for the largest k whose entries fit),
/// or none (solve b whole) when that leaves more than kSupportedShare of the rows.
std::vector<Eigen::Index> load_support(const Vector& b, double dropped_norm) {
  constexpr int kShift = 1080;  // frexp's exponents of doubles (-1073 to 1024) shifted to >= 0
  constexpr int kExponents = 2110;
  std::vector<int> exponent_of(static_cast<std::size_t>(b.size()));
  std::vector<double> square_sum(kExponents, 0.0);
  for (Eigen::Index i = 0; i < b.size(); ++i) {
    int exponent = 0;
    std::frexp(b[i], &exponent);
    const int bucket = std::clamp(exponent + kShift, 0, kExponents - 1);
    exponent_of[static_cast<std::size_t>(i)] = bucket;
    square_sum[static_cast<std::size_t>(bucket)] += b[i] * b[i];
  }
  double dropped = 0.0;
  int kept_from = 0;  // the entries of the buckets below are left out
  while (kept_from < kExponents && dropped + square_sum[static_cast<std::size_t>(kept_from)] <= dropped_norm * dropped_norm)
    dropped += square_sum[static_cast<std::size_t>(kept_from++)];
  std::vector<Eigen::Index> support;
  for (Eigen::Index i = 0; i < b.size(); ++i)
    if (b[i] != 0.0 && exponent_of[static_cast<std::size_t>(i)] >= kept_from) support.push_back(i);
  if (static_cast<double>(support.size()) > kSupportedShare * static_cast<double>(b.size())) support.clear();
  return support;
}

class CholmodSolver final : public LinearSolver {
 public:
  explicit CholmodSolver(const SolveSettings& settings) : settings_(settings) {
    cholmod_start(&common_);
    common_.supernodal = CHOLMOD_SUPERNODAL;
    common_.print = 0;
    common_.error_handler = nullptr;
  }
  ~CholmodSolver() override {
    if (factor_ != nullptr) cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  void setup(const SparseMatrix& a, const LinkedVolume& topology) override { setup_taking(SparseMatrix(a), topology); }

  void setup_taking(SparseMatrix&& a, const LinkedVolume& /*topology*/) override {
    a_.swap(a);  // Eigen 3.4's SparseMatrix has no move assignment: std::move would copy
    a_.makeCompressed();
    const auto n = static_cast<std::size_t>(a_.rows());
    // A symmetric CSR matrix read as CSC is the same matrix; stype 1 reads its upper triangle.
    cholmod_sparse view{};
    view.nrow = n;
    view.ncol = n;
    view.nzmax = static_cast<std::size_t>(a_.nonZeros());
    view.p = a_.outerIndexPtr();
    view.i = a_.innerIndexPtr();
    view.x = a_.valuePtr();
    view.stype = 1;
    view.itype = CHOLMOD_INT;
    view.xtype = CHOLMOD_REAL;
    view.dtype = CHOLMOD_DOUBLE;
    view.sorted = 1;
    view.packed = 1;

    const bool same_pattern = factor_ != nullptr && pattern_outer_.size() == n + 1 &&
                              std::equal(pattern_outer_.begin(), pattern_outer_.end(), a_.outerIndexPtr()) &&
                              pattern_inner_.size() == view.nzmax &&
                              std::equal(pattern_inner_.begin(), pattern_inner_.end(), a_.innerIndexPtr());
    if (!same_pattern) {
      substitution_.reset();
      if (factor_ != nullptr) cholmod_free_factor(&factor_, &common_);
      factor_ = cholmod_analyze(&view, &common_);
      if (factor_ == nullptr) throw ComputeError(fmt::format("cholmod: analysis failed (status {})", common_.status));
      pattern_outer_.assign(a_.outerIndexPtr(), a_.outerIndexPtr() + n + 1);
      pattern_inner_.assign(a_.innerIndexPtr(), a_.innerIndexPtr() + view.nzmax);
    }
    cholmod_factorize(&view, factor_, &common_);
    if (common_.status == CHOLMOD_NOT_POSDEF || factor_->minor < n) {
      const std::size_t minor = factor_->minor;
      const int dof = minor < n && factor_->Perm != nullptr ? static_cast<const int*>(factor_->Perm)[minor] : -1;
      pattern_outer_.clear();  // force a fresh analysis next time
      substitution_.reset();
      cholmod_free_factor(&factor_, &common_);
      throw ComputeError(fmt::format(
          "cholmod: matrix is not positive definite (pivot {} of {} fails, dof {} of vertex {}); a piece without fixed "
          "vertices leaves rigid motions free",
          minor, n, dof, dof >= 0 ? dof / 3 : -1));
    }
    if (common_.status < CHOLMOD_OK) throw ComputeError(fmt::format("cholmod: factorization failed (status {})", common_.status));
    if (settings_.parallel_substitution && !substitution_) substitution_.emplace(*factor_);
    single_values_.clear();
    if (substitution_ && settings_.single_precision_factor) single_values_ = substitution_->single_precision_values(*factor_);
  }

  SolveReport solve(const Vector& b, Vector& x) override {
    SolveReport report;
    if (factor_ == nullptr) throw ComputeError("cholmod: solve called before a successful setup");
    if (b.size() != a_.rows())
      throw InputError(fmt::format("cholmod: right-hand side has {} entries; the matrix set up has {} rows", b.size(), a_.rows()));
    const double b_norm = b.norm();
    if (x.size() != b.size() || !x.allFinite()) x = Vector::Zero(b.size());
    if (!(b_norm > 0)) {
      x.setZero();
      report.converged = std::isfinite(b_norm);
      return report;
    }
    Vector r;
    if (!single_values_.empty() && solve_single_refined(b, b_norm, x, r, report)) return report;
    if (substitution_) {
      Vector solved = b;
      substitution_->solve(*factor_, solved);
      if (solved.allFinite()) x = solved;
    } else {
      solve_with_cholmod(b, x);
    }
    ++report.iterations;
    residual(a_, b, x, r);
    report.relative_residual = r.norm() / b_norm;
    report.converged = report.relative_residual <= settings_.relative_tolerance;
    return report;
  }

  std::string_view name() const override { return "cholmod"; }

 private:
  /// x = A^-1 b with the single-precision factor: a substitution, then refinements of the
  /// residual (computed in double) until it meets the tolerance. False when it does not within
  /// kMaxSingleSubstitutions, or a value leaves float's range: the double factor then solves
  /// (the substitutions done are counted in report.iterations).
  bool solve_single_refined(const Vector& b, double b_norm, Vector& x, Vector& r, SolveReport& report) {
    Vector trial = Vector::Zero(b.size());
    r = b;
    for (int step = 0; step < kMaxSingleSubstitutions; ++step) {
      if (!r.cast<float>().allFinite()) return false;
      Vector correction = r;
      const std::vector<Eigen::Index> support =
          step == 0 ? load_support(r, kDroppedShareOfTolerance * settings_.relative_tolerance * b_norm) : std::vector<Eigen::Index>{};
      if (support.empty())
        substitution_->solve_single(*factor_, single_values_, correction);
      else
        substitution_->solve_single_supported(*factor_, single_values_, support, correction);
      ++report.iterations;
      if (!correction.allFinite()) return false;
      trial += correction;
      residual(a_, b, trial, r);
      report.relative_residual = r.norm() / b_norm;
      if (report.relative_residual <= settings_.relative_tolerance) {
        x = trial;
        report.converged = true;
        return true;
      }
    }
    return false;
  }

  /// x = A^-1 b by cholmod_solve (x unchanged when the result is not finite).
  void solve_with_cholmod(const Vector& b, Vector& x) {
    cholmod_dense rhs{};
    rhs.nrow = static_cast<std::size_t>(b.size());
    rhs.ncol = 1;
    rhs.nzmax = rhs.nrow;
    rhs.d = rhs.nrow;
    rhs.x = const_cast<double*>(b.data());  // cholmod_solve only reads it
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* solution = cholmod_solve(CHOLMOD_A, factor_, &rhs, &common_);
    if (solution != nullptr) {
      const Eigen::Map<const Vector> values(static_cast<const double*>(solution->x), b.size());
      if (values.allFinite()) x = values;
      cholmod_free_dense(&solution, &common_);
    }
  }

  SolveSettings settings_;
  SparseMatrix a_;
  cholmod_common common_{};
  cholmod_factor* factor_ = nullptr;
  std::optional<SupernodalSubstitution> substitution_;  ///< with parallel_substitution: the schedule of factor_
  std::vector<float> single_values_;  ///< with single_precision_factor: factor_'s values in float
  std::vector<int> pattern_outer_, pattern_inner_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_cholmod_solver(const SolveSettings& settings) {
  return std::make_unique<CholmodSolver>(settings);
}

}  // namespace cleave
