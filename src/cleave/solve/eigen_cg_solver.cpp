#include "cleave/solve/eigen_cg_solver.hpp"

#include <fmt/format.h>

#include <Eigen/IterativeLinearSolvers>
#include <utility>

#include "cleave/core/error.hpp"
#include "cleave/solve/sparse_multiply.hpp"

namespace cleave {
namespace {

class EigenCgSolver final : public LinearSolver {
 public:
  explicit EigenCgSolver(const SolveSettings& settings) : settings_(settings) {}

  void setup(const SparseMatrix& a, const LinkedVolume& topology) override { setup_taking(SparseMatrix(a), topology); }

  void setup_taking(SparseMatrix&& a, const LinkedVolume& /*topology*/) override {
    a_.swap(a);  // Eigen 3.4's SparseMatrix has no move assignment: std::move would copy
    a_.makeCompressed();
    cg_.setTolerance(settings_.relative_tolerance);
    cg_.setMaxIterations(settings_.max_iterations);
    // A symmetric CSR matrix read as CSC is the same matrix: hand Eigen a column-major view.
    view_ = std::make_unique<ColumnView>(a_.rows(), a_.cols(), a_.nonZeros(), a_.outerIndexPtr(), a_.innerIndexPtr(), a_.valuePtr());
    cg_.compute(*view_);
  }

  SolveReport solve(const Vector& b, Vector& x) override {
    SolveReport report;
    if (b.size() != a_.rows())
      throw InputError(fmt::format("eigen-cg: right-hand side has {} entries; the matrix set up has {} rows", b.size(), a_.rows()));
    if (x.size() != b.size() || !x.allFinite()) x = Vector::Zero(b.size());
    const double b_norm = b.norm();
    if (!(b_norm > 0)) {
      x.setZero();
      report.converged = std::isfinite(b_norm);
      return report;
    }
    Vector next = cg_.solveWithGuess(b, x);
    if (next.allFinite()) x = std::move(next);
    report.iterations = static_cast<int>(cg_.iterations());
    Vector r;
    residual(a_, b, x, r);
    report.relative_residual = r.norm() / b_norm;
    report.converged = cg_.info() == Eigen::Success && report.relative_residual <= settings_.relative_tolerance;
    return report;
  }

  std::string_view name() const override { return "eigen-cg"; }

 private:
  SolveSettings settings_;
  using ColumnView = Eigen::Map<const Eigen::SparseMatrix<double>>;
  SparseMatrix a_;
  std::unique_ptr<ColumnView> view_;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_eigen_cg_solver(const SolveSettings& settings) {
  return std::make_unique<EigenCgSolver>(settings);
}

}  // namespace cleave
