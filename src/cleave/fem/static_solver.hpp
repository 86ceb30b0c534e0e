#pragma once
// Statics for many loads on one model: the stiffness is assembled, the supports chosen and the
// linear solver set up (a CHOLMOD factor, a multigrid hierarchy) once; each solve then costs one
// right-hand side. The studio keeps one per cut state, so a design edit that changes only the
// residual stress re-solves without refactoring.
//
//   StaticSolver statics(cut_model, options);          // assemble + factor once
//   StaticResult a = statics.solve(stress_kPa);        // K u = f - T sigma
//   StaticResult b = statics.solve(other_stress_kPa);  // same factor
//
// The model must outlive the solver and keep its topology (no cut) while the solver is used.
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "cleave/core/recent_results.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/rigid_supports.hpp"
#include "cleave/fem/solve_static.hpp"

namespace cleave {

class StaticSolver {
 public:
  /// Assembles the model's stiffness. Throws InputError for a mismatched external force.
  StaticSolver(const TissueModel& model, const StaticOptions& options);
  /// With an assembled stiffness of the model's current topology (see assemble_stiffness.hpp).
  StaticSolver(const TissueModel& model, SparseMatrix stiffness, const StaticOptions& options);

  /// Solves K u = f - T sigma (f: the options' external force) as solve_static does; the solver
  /// is set up at the first loaded solve and kept. A stress equal (bit for bit) to one of the
  /// last two solved is answered from memory (`remembered` set, no solve: undo, redo, a drag
  /// back in the studio). Throws as solve_static.
  StaticResult solve(std::span<const Vec6> residual_stress_kPa);
  /// The same without remembering (nor looking up) the stress and its result: solve_static's
  /// one-shot use, which would only copy both (~70 MB at a million cells).
  StaticResult solve_once(std::span<const Vec6> residual_stress_kPa);

  /// Sets the linear solver up now (a CHOLMOD factorization, a multigrid hierarchy) instead of at
  /// the first loaded solve, e.g. on another thread while the caller shows something else; then
  /// the first solve costs one solve. Does nothing when it is set up.
  void set_up_solver();

  int solves() const { return solves_; }  ///< loaded solves done (not the remembered answers)
  bool set_up() const { return set_up_; }

 private:
  static constexpr std::size_t kRememberedLoads = 2;

  const TissueModel& model_;
  StaticOptions options_;
  SparseMatrix eliminated_;  ///< K with the held dofs' rows and columns replaced by identity; given to the solver at set-up
  Vector fixed_load_;        ///< the right-hand side that elimination makes of a zero load
  FixedDofs fixed_;
  RigidSupportReport supports_;
  std::optional<RigidMotionRemover> rigid_motion_;  ///< of the free pieces, set up at the first loaded solve
  std::unique_ptr<LinearSolver> solver_;
  bool set_up_ = false;
  int solves_ = 0;
  RecentResults<std::vector<Vec6>, StaticResult> recent_{kRememberedLoads};
};

}  // namespace cleave
