#pragma once
// cleave's default solver: conjugate gradients preconditioned by a cut-aware geometric multigrid
// V-cycle on the linked volume (multigrid_preconditioner.hpp), warm-started from x.
//
//   auto s = make_multigrid_cg_solver(settings);   // or make_linear_solver(SolverKind::multigrid_cg)
//   s->setup(a, volume);                           // builds the coarse levels and operators
//   s->solve(b, x);
// solve() throws InputError when b does not match the matrix given to setup().
#include <memory>

#include "cleave/solve/linear_solver.hpp"
#include "cleave/solve/multigrid_preconditioner.hpp"

namespace cleave {

std::unique_ptr<LinearSolver> make_multigrid_cg_solver(const SolveSettings& settings, const MultigridOptions& options = {});

}  // namespace cleave
