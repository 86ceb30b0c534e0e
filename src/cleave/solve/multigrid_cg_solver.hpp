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

/// The iterations `report`'s solve would have needed to cut its initial residual by
/// `target_reduction` (0 < target < 1) at the mean rate per iteration it reached: its own count when
/// it converged; more when an iteration budget stopped it first (the dynamic step's
/// DynamicsSettings::iterations_per_step); infinity when it reduced nothing. The multigrid's rule
/// for rebuilding stale levels compares these, so that it still sees a budgeted step's levels
/// grow stale.
double iterations_at_reached_rate(const SolveReport& report, double target_reduction);

}  // namespace cleave
