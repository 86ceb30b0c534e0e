#pragma once
// Peer solver: Eigen's ConjugateGradient preconditioned by Eigen's IncompleteCholesky (with its
// automatic diagonal shift), warm-started from x. Single-threaded as Eigen ships it; used to
// check cleave's solvers and as a benchmark reference.
//
//   auto s = make_eigen_cg_solver(settings);   // or make_linear_solver(SolverKind::eigen_cg)
//   s->setup(a, volume);  s->solve(b, x);
//
// The report gives Eigen's iteration count and the true relative residual ||b - A x|| / ||b||;
// x is left at its initial guess if Eigen returns a non-finite result.
#include <memory>

#include "cleave/solve/linear_solver.hpp"

namespace cleave {

std::unique_ptr<LinearSolver> make_eigen_cg_solver(const SolveSettings& settings);

}  // namespace cleave
