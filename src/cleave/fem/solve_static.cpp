#include "cleave/fem/solve_static.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/residual_stress_forces.hpp"
#include "cleave/fem/rigid_supports.hpp"

namespace cleave {

void require_converged(const SolveReport& report, std::string_view solver, const SolveSettings& settings,
                       const std::string& what) {
  if (report.converged && std::isfinite(report.relative_residual)) return;
  throw ComputeError(fmt::format("{} did not converge with {}: relative residual {:.3g} after {} iterations (tolerance {:.3g})",
                                 what, solver, report.relative_residual, report.iterations, settings.relative_tolerance));
}

StaticResult solve_static(const TissueModel& model, const SparseMatrix& stiffness, std::span<const Vec6> residual_stress_kPa,
                          const StaticOptions& options) {
  const LinkedVolume& volume = model.volume;
  const auto dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  if (stiffness.rows() != dofs)
    throw InputError(fmt::format("stiffness has {} rows; expected {} (3 per vertex of the current model)", stiffness.rows(), dofs));
  if (options.external_force_mN.size() != 0 && options.external_force_mN.size() != dofs)
    throw InputError(fmt::format("external force holds {} values; expected {} (3 per vertex)", options.external_force_mN.size(), dofs));

  Vector b = Vector::Zero(dofs);
  if (!residual_stress_kPa.empty()) b -= residual_stress_forces(volume, residual_stress_kPa);
  if (options.external_force_mN.size() != 0) b += options.external_force_mN;
  FixedDofs fixed = fix_vertices(volume.vertex_count(), options.fixed_vertices, options.fixed_displacement_mm);

  StaticResult result;
  result.displacement_mm.assign(static_cast<std::size_t>(volume.vertex_count()), Vec3::Zero());
  const bool loaded = b.lpNorm<Eigen::Infinity>() > 0 || fixed.value_mm.lpNorm<Eigen::Infinity>() > 0;
  const RigidSupportReport supports = add_rigid_supports(volume, fixed);
  result.free_components = static_cast<int>(supports.free_components.size());
  auto solver = make_linear_solver(options.solver, options.settings);
  result.solver_name = std::string(solver->name());
  if (!loaded) {
    result.report.converged = true;
    return result;
  }

  SparseMatrix a = stiffness;
  eliminate_fixed_dofs(a, b, fixed);
  Vector u = fixed.value_mm;
  solver->setup(a, volume);
  result.report = solver->solve(b, u);
  require_converged(result.report, solver->name(), options.settings, "static solve");
  remove_rigid_motion(volume, supports.free_components, lumped_mass(model), u);
  if (!u.allFinite()) throw ComputeError(fmt::format("static solve with {} produced a non-finite displacement", solver->name()));
  for (VertexId v = 0; v < volume.vertex_count(); ++v) result.displacement_mm[static_cast<std::size_t>(v)] = u.segment<3>(3 * v);
  return result;
}

StaticResult solve_static(const TissueModel& model, std::span<const Vec6> residual_stress_kPa, const StaticOptions& options) {
  return solve_static(model, assemble_stiffness(model), residual_stress_kPa, options);
}

}  // namespace cleave
