// make_linear_solver, solver_kind_from_name, solver_kind_name (declared in linear_solver.hpp).
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/solve/cholmod_solver.hpp"
#include "cleave/solve/eigen_cg_solver.hpp"
#include "cleave/solve/linear_solver.hpp"
#include "cleave/solve/multigrid_cg_solver.hpp"

namespace cleave {

SolverKind solver_kind_from_name(std::string_view name) {
  for (const SolverKind kind : {SolverKind::multigrid_cg, SolverKind::eigen_cg, SolverKind::cholmod})
    if (solver_kind_name(kind) == name) return kind;
  throw InputError(fmt::format("unknown solver '{}'; expected one of multigrid, eigen-cg, cholmod", name));
}

std::string_view solver_kind_name(SolverKind kind) {
  switch (kind) {
    case SolverKind::multigrid_cg: return "multigrid";
    case SolverKind::eigen_cg: return "eigen-cg";
    case SolverKind::cholmod: return "cholmod";
  }
  return "multigrid";
}

std::unique_ptr<LinearSolver> make_linear_solver(SolverKind kind, const SolveSettings& settings) {
  switch (kind) {
    case SolverKind::multigrid_cg: return make_multigrid_cg_solver(settings);
    case SolverKind::eigen_cg: return make_eigen_cg_solver(settings);
    case SolverKind::cholmod: return make_cholmod_solver(settings);
  }
  return make_multigrid_cg_solver(settings);
}

}  // namespace cleave
