#include "cleave/fem/solve_static.hpp"

#include <fmt/format.h>

#include <utility>

#include "cleave/core/error.hpp"
#include "cleave/fem/static_solver.hpp"

namespace cleave {

void require_converged(const SolveReport& report, std::string_view solver, const SolveSettings& settings,
                       const std::string& what) {
  if (report.converged && std::isfinite(report.relative_residual)) return;
  throw ComputeError(fmt::format("{} did not converge with {}: relative residual {:.3g} after {} iterations (tolerance {:.3g})",
                                 what, solver, report.relative_residual, report.iterations, settings.relative_tolerance));
}

StaticOptions preview_static_options(std::vector<VertexId> held_vertices) {
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.settings.relative_tolerance = kPreviewRelativeResidual;
  options.settings.single_precision_factor = true;
  options.fixed_vertices = std::move(held_vertices);
  return options;
}

StaticResult solve_static(const TissueModel& model, const SparseMatrix& stiffness, std::span<const Vec6> residual_stress_kPa,
                          const StaticOptions& options) {
  return StaticSolver(model, stiffness, options).solve_once(residual_stress_kPa);
}

StaticResult solve_static(const TissueModel& model, std::span<const Vec6> residual_stress_kPa, const StaticOptions& options) {
  return StaticSolver(model, options).solve_once(residual_stress_kPa);
}

}  // namespace cleave
