#include "cleave/solve/multigrid_cg_solver.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/solve/conjugate_gradient.hpp"
#include "cleave/solve/multigrid_preconditioner.hpp"

namespace cleave {
namespace {

class MultigridCgSolver final : public LinearSolver {
 public:
  MultigridCgSolver(const SolveSettings& settings, const MultigridOptions& options) : settings_(settings), options_(options) {}

  void setup(const SparseMatrix& a, const LinkedVolume& topology) override {
    preconditioner_ = MultigridPreconditioner();  // drops the reference to the old matrix first
    a_ = a;
    a_.makeCompressed();
    preconditioner_ = build_multigrid(a_, topology, options_);
  }

  SolveReport solve(const Vector& b, Vector& x) override {
    if (b.size() != a_.rows())
      throw InputError(fmt::format("multigrid: right-hand side has {} entries; the matrix set up has {} rows", b.size(), a_.rows()));
    return preconditioned_cg(a_, b, x, preconditioner_, settings_);
  }

  std::string_view name() const override { return "multigrid"; }

 private:
  SolveSettings settings_;
  MultigridOptions options_;
  SparseMatrix a_;
  MultigridPreconditioner preconditioner_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_multigrid_cg_solver(const SolveSettings& settings, const MultigridOptions& options) {
  return std::make_unique<MultigridCgSolver>(settings, options);
}

}  // namespace cleave
