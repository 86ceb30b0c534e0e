#pragma once
// Peer solver: SuiteSparse CHOLMOD supernodal sparse Cholesky (direct). The symbolic analysis
// (fill-reducing ordering) is kept while the sparsity pattern stays the same, so refactoring a
// matrix with new values (a time step, a corotated operator) skips it.
//
//   auto s = make_cholmod_solver(settings);   // or make_linear_solver(SolverKind::cholmod)
//   s->setup(a, volume);                      // analysis + numeric factorization
//   s->solve(b, x);                           // x = A^-1 b (the initial guess is not needed)
//
// A matrix that is not positive definite (e.g. a piece held by no fixed vertex: its rigid
// motions make A singular even when the load is consistent) cannot be factored: setup throws
// ComputeError "cholmod: matrix is not positive definite (pivot N of M); ..." naming the dof's
// vertex. The report gives 1 iteration and the true relative residual.
#include <memory>

#include "cleave/solve/linear_solver.hpp"

namespace cleave {

std::unique_ptr<LinearSolver> make_cholmod_solver(const SolveSettings& settings);

}  // namespace cleave
