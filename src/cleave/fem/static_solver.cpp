#include "cleave/fem/static_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "cleave/core/error.hpp"
#include "cleave/core/units.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/residual_stress_forces.hpp"

namespace cleave {

StaticSolver::StaticSolver(const TissueModel& model, const StaticOptions& options)
    : StaticSolver(model, assemble_stiffness(model), options) {}

StaticSolver::StaticSolver(const TissueModel& model, SparseMatrix stiffness, const StaticOptions& options)
    : model_(model), options_(options) {
  eliminated_.swap(stiffness);  // Eigen 3.4's SparseMatrix has no move constructor: std::move would copy
  const LinkedVolume& volume = model.volume;
  const auto dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  if (eliminated_.rows() != dofs)
    throw InputError(fmt::format("stiffness has {} rows; expected {} (3 per vertex of the current model)", eliminated_.rows(), dofs));
  if (options.external_force_mN.size() != 0 && options.external_force_mN.size() != dofs)
    throw InputError(fmt::format("external force holds {} values; expected {} (3 per vertex)", options.external_force_mN.size(), dofs));
  fixed_ = fix_vertices(volume.vertex_count(), options.fixed_vertices, options.fixed_displacement_mm);
  supports_ = add_rigid_supports(volume, fixed_);
  // Elimination is linear in the load: b = (f with the held entries zeroed) + fixed_load_.
  fixed_load_ = Vector::Zero(dofs);
  eliminate_fixed_dofs(eliminated_, fixed_load_, fixed_);
  solver_ = make_linear_solver(options.solver, options.settings);
}

void StaticSolver::set_up_solver() {
  if (set_up_) return;
  solver_->setup_taking(std::move(eliminated_), model_.volume);  // the solver keeps what it needs of it
  eliminated_ = SparseMatrix();  // emptied whether or not the solver swapped it out
  set_up_ = true;
}

StaticResult StaticSolver::solve(std::span<const Vec6> residual_stress_kPa) {
  if (const StaticResult* known = recent_.find(residual_stress_kPa)) {
    StaticResult recalled = *known;
    recalled.remembered = true;
    return recalled;
  }
  StaticResult result = solve_once(residual_stress_kPa);
  recent_.remember({residual_stress_kPa.begin(), residual_stress_kPa.end()}, result);
  return result;
}

StaticResult StaticSolver::solve_once(std::span<const Vec6> residual_stress_kPa) {
  const LinkedVolume& volume = model_.volume;
  const auto dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  Vector f = Vector::Zero(dofs);
  if (!residual_stress_kPa.empty()) f -= residual_stress_forces(volume, residual_stress_kPa);
  if (options_.external_force_mN.size() != 0) f += options_.external_force_mN;
  if (!std::isfinite(f.squaredNorm())) {  // also finite entries whose squares overflow (CG's dot products)
    double largest_kPa = 0;
    for (const Vec6& s : residual_stress_kPa) largest_kPa = std::max(largest_kPa, s.cwiseAbs().maxCoeff());
    throw ComputeError(fmt::format("static solve: the load overflows double precision (largest residual stress {:.3g} kPa); expected "
                                   "finite stresses of at most {:.0e} kPa and finite external forces",
                                   largest_kPa, units::kLargestStress_kPa));
  }

  StaticResult result;
  result.displacement_mm.assign(static_cast<std::size_t>(volume.vertex_count()), Vec3::Zero());
  result.free_components = static_cast<int>(supports_.free_components.size());
  result.solver_name = std::string(solver_->name());
  if (!(f.lpNorm<Eigen::Infinity>() > 0 || fixed_.value_mm.lpNorm<Eigen::Infinity>() > 0)) {
    result.report.converged = true;
    return result;
  }
  for (Eigen::Index j = 0; j < dofs; ++j)
    if (fixed_.fixed[static_cast<std::size_t>(j)] != 0) f[j] = 0.0;
  f += fixed_load_;
  set_up_solver();
  Vector u = fixed_.value_mm;
  result.report = solver_->solve(f, u);
  ++solves_;
  require_converged(result.report, solver_->name(), options_.settings, "static solve");
  if (!rigid_motion_) rigid_motion_.emplace(volume, supports_.free_components, lumped_mass(model_));
  rigid_motion_->remove(u);
  if (!u.allFinite()) throw ComputeError(fmt::format("static solve with {} produced a non-finite displacement", solver_->name()));
  for (VertexId v = 0; v < volume.vertex_count(); ++v) result.displacement_mm[static_cast<std::size_t>(v)] = u.segment<3>(3 * v);
  return result;
}

}  // namespace cleave
