#pragma once
// How each implementation runs the solver-backed stages (incision preview, dynamic step):
//   cleave    multigrid CG on every TBB worker
//   paper     the same multigrid CG on one thread (the paper's simulation used the geometric
//             multigrid of Dick et al. 2011 on one core)
//   eigen_cg  Eigen's ConjugateGradient with incomplete Cholesky
//   cholmod   SuiteSparse CHOLMOD as shipped (substitution by cholmod_solve)
//
//   ImplementationScope scope(Implementation::paper);   // limits TBB to one thread until destroyed
//   SolverKind kind = scope.solver();
#include <memory>

#include <tbb/global_control.h>

#include "bench_figures.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave::bench {

/// The linear solver an implementation uses for the mechanics stages.
SolverKind solver_of(Implementation implementation);

/// Threads an implementation may use: 1 for the paper's algorithms, all otherwise.
class ImplementationScope {
 public:
  explicit ImplementationScope(Implementation implementation);
  SolverKind solver() const { return solver_; }
  /// Whether CHOLMOD's factor is substituted on all cores: cleave's own use of it, not the peer's.
  bool parallel_substitution() const { return parallel_substitution_; }

 private:
  SolverKind solver_;
  bool parallel_substitution_;
  std::unique_ptr<tbb::global_control> one_thread_;
};

/// ||a - b|| / ||b|| (b is the reference); 0 when both are zero; InputError for different sizes.
double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

}  // namespace cleave::bench
