#pragma once
// Statics with residual stress: the deformation once residual stress is released (by cuts or a
// free surface), from  K u = f - T sigma  on the current (possibly cut) linked volume.
//
//   StaticOptions options;
//   options.solver = SolverKind::cholmod;
//   options.fixed_vertices = vertices_in_box(model.volume, lo, hi);   // or leave empty: free body
//   StaticResult r = solve_static(model, stress_kPa, options);
//   r.displacement_mm[v]                                              // mm per vertex
//
// Free pieces (no fixed vertex, e.g. the plug of a round incision or the whole body): each gets
// a 3-2-1 support (rigid_supports.hpp) that carries no reaction for a self-equilibrated load such
// as T sigma, and its rigid motion is removed afterwards (mass-weighted), so it stays in place.
// External forces on a free piece that are not in balance are taken by that support.
// Errors: InputError for mismatched sizes; ComputeError (with the residual reached) when the
// solver does not converge or the result is not finite. No NaN is ever returned.
#include <span>
#include <string>
#include <vector>

#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/model/tissue_model.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

struct StaticOptions {
  SolverKind solver = SolverKind::multigrid_cg;
  SolveSettings settings;
  std::vector<VertexId> fixed_vertices;     ///< held vertices (Dirichlet)
  std::vector<Vec3> fixed_displacement_mm;  ///< their prescribed displacement; empty = all zero
  Vector external_force_mN;                 ///< 3 n_v nodal forces f; empty = none
};

/// The incision preview's statics: the picture the studio draws after every design edit (and the
/// bench's edit-to-picture update, which times it). A picture and its ellipse measurements, solved
/// to a relative residual of 1e-4 with the single-precision copy of CHOLMOD's factor (half the
/// bytes of a substitution with the double one). Measured in session 28 (one float substitution,
/// against the double solve): the incised abdomen at 45k cells, residual 8.5e-6 to 9.3e-6,
/// displacement 2.6e-5 to 2.9e-4 of its norm off (0.16 um at most, on openings of 0.6 mm); the
/// incised 44k tube 1.2e-5 and 2e-6 to 6e-6 (11 nm of 2.7 mm): far below a pixel and a cell
/// (1-2 mm). Batch runs (`cleave run`, the demo) keep SolveSettings' 1e-8.
inline constexpr double kPreviewRelativeResidual = 1e-4;
/// CHOLMOD with the single-precision factor at kPreviewRelativeResidual, `held_vertices` at rest.
StaticOptions preview_static_options(std::vector<VertexId> held_vertices);

struct StaticResult {
  std::vector<Vec3> displacement_mm;  ///< per vertex
  SolveReport report;                 ///< iterations 0 when no solve was needed (zero load)
  std::string solver_name;
  int free_components = 0;            ///< pieces that no fixed vertex held
  bool remembered = false;            ///< StaticSolver: an earlier solve's result for the same stress (no solve)
};

StaticResult solve_static(const TissueModel& model, std::span<const Vec6> residual_stress_kPa,
                          const StaticOptions& options);
/// Same with an assembled stiffness of the model's current topology (see assemble_stiffness.hpp).
StaticResult solve_static(const TissueModel& model, const SparseMatrix& stiffness,
                          std::span<const Vec6> residual_stress_kPa, const StaticOptions& options);

/// Throws ComputeError "<what> did not converge with <solver>: relative residual R after N
/// iterations (tolerance T)" when the report says so.
void require_converged(const SolveReport& report, std::string_view solver, const SolveSettings& settings,
                       const std::string& what);

}  // namespace cleave
