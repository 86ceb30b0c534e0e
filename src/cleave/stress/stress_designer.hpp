#pragma once
// The residual stress design of one tissue model, kept up to date while the user edits
// (issue 4, items 1 to 7). It holds the model's operators (Laplacians, T, its norm, the surface
// normal field, symbolic factorizations) so that each edit only redoes what depends on it:
//   stroke edits          -> Langer line field, frames, stress (and the eigenvalues when w_E > 0:
//                            without the equilibrium rows they do not depend on the frames)
//   control point edits   -> eigenvalues, stress (frames are kept); a change of values only is
//                            one solve with the kept eigenvalue factor
// Warm start: every factorization (Langer field, eigenvalues, the equilibration's Kc) is kept;
// after an edit it preconditions CG on the edited system from the previous solution, and a
// system is refactorized only when that CG is off track or would cost more than a new factor
// (stroke edits of the Langer field; SparseCholesky::solve_with_current_factor decides on
// measured times). The paper CG starts from the previous eigenvalues. Non-finite intermediate
// results are ComputeErrors naming the stage, never a NaN in the result. An edit gives the same result as a fresh
// designer with the final design (within solver tolerance).
//
//   StressDesigner designer(model, design);         // computes everything; InputError on bad design
//   designer.add_stroke({{p0, p1, p2}});            // recomputes
//   designer.move_control_point(0, {q, 25, 12});
//   const DesignResult& r = designer.result();      // frames, eigenvalues, stress per cell
//
// The last two designs are remembered with their results: an edit back to one of them (compared
// exactly: strokes, control points, solver, equilibration) is answered without redoing a stage
// (DesignResult::remembered).
//
// A picture before the last digits (EquilibrationPass::picture, stress/equilibrate_stress.hpp): an
// edit may return a provisional stress, equilibrated to 1e-6 of the designed forces instead of
// 5e-11, which the picture cannot tell apart; finish_equilibration() then completes it to what the
// complete pass gives, bit for bit. A provisional result is not remembered (see above) until
// completed; the next edit drops it.
//
//   designer.set_design(d, EquilibrationPass::picture);
//   draw(designer.result());                        // result().provisional may be true
//   designer.finish_equilibration();                // result() as set_design(d) would give
//
// The model must outlive the designer and keep its topology (build a new designer after a cut).
// Edits that fail validation throw InputError and leave the designer unchanged. Indices out of
// range are InputErrors too.
#include <memory>
#include <vector>

#include "cleave/core/recent_results.hpp"
#include "cleave/model/tissue_model.hpp"
#include "cleave/stress/direction_frames.hpp"
#include "cleave/stress/equilibrate_stress.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave {

/// Wall-clock time of each step of the last update (s); 0 for steps that were not redone.
struct DesignTimings {
  double directions_s = 0;    ///< stroke targets, Langer field, orthonormal frames
  double eigenvalues_s = 0;   ///< eigenvalue least squares (0 when an edit cannot change them)
  double equilibration_s = 0; ///< exact equilibration (when enabled)
};

struct DesignResult {
  std::vector<DirectionFrame> frames;    ///< per cell
  std::vector<Vec3> eigenvalues_kPa;     ///< per cell: Langer, cross, normal (of the design, before equilibration)
  std::vector<Vec6> designed_kPa;        ///< sigma from frames and eigenvalues (eq. 4)
  std::vector<Vec6> stress_kPa;          ///< the result: designed_kPa, equilibrated when enabled
  double residual_designed = 0;          ///< ||T sigma|| / (||T||_2 ||sigma||) of designed_kPa (free vertices)
  double residual_final = 0;             ///< the same of stress_kPa
  int eigenvalue_iterations = 0;         ///< CG iterations of the last eigenvalue solve (paper CG; for the default, CG
                                         ///< with the kept factor, 0 = direct solve or not redone)
  int equilibration_iterations = 0;      ///< CG iterations of the last equilibration (0 = none or already balanced)
  /// The design equals one of the last two (undo, redo, a stroke dragged back): this is the
  /// result computed for it then, and no stage was redone (timings 0).
  bool remembered = false;
  /// stress_kPa is the equilibration's provisional result (EquilibrationPass::picture):
  /// StressDesigner::finish_equilibration() completes it; residual_final is its own.
  bool provisional = false;
  DesignTimings timings;
};

class StressDesigner {
 public:
  StressDesigner(const TissueModel& model, StressDesign design);
  ~StressDesigner();
  StressDesigner(const StressDesigner&) = delete;
  StressDesigner& operator=(const StressDesigner&) = delete;

  const StressDesign& design() const { return design_; }
  const DesignResult& result() const { return result_; }

  void add_stroke(DesignStroke stroke);
  void move_stroke(std::size_t index, DesignStroke stroke);  ///< replaces stroke `index`
  void delete_stroke(std::size_t index);
  void add_control_point(DesignControlPoint point);
  void move_control_point(std::size_t index, DesignControlPoint point);
  void delete_control_point(std::size_t index);
  /// Replaces the whole design (weights and solver must stay the same: InputError otherwise).
  /// With EquilibrationPass::picture the result may be provisional (see above).
  void set_design(StressDesign design, EquilibrationPass pass = EquilibrationPass::complete);
  /// Completes a provisional result (nothing to do otherwise): the equilibration's remaining
  /// steps; timings.equilibration_s then holds both parts. When they fail (ComputeError), the
  /// designer returns to the design before the edit, as a failing set_design leaves it, and rethrows.
  void finish_equilibration();

 private:
  struct Operators;
  /// What a result depends on besides the designer's fixed settings (weights, snap tolerance,
  /// held vertices: set_design refuses changes of those).
  struct DesignKey {
    std::vector<DesignStroke> strokes;
    std::vector<DesignControlPoint> control_points;
    EigenvalueSolver solver = EigenvalueSolver::cholesky;
    Equilibration equilibration = Equilibration::growth;
    bool operator==(const DesignKey& other) const;
  };
  static DesignKey key_of(const StressDesign& design);
  void update_directions(const StressDesign& design, DesignResult& out);
  void update_eigenvalues(const StressDesign& design, DesignResult& out);
  void finish(const StressDesign& design, DesignResult& out, EquilibrationPass pass);
  /// The equilibration's figures in `out` (stress, iterations, residuals, provisional).
  void take_equilibration(EquilibrationResult balanced, DesignResult& out) const;

  const TissueModel& model_;
  StressDesign design_;
  std::unique_ptr<Operators> ops_;
  DesignResult result_;
  RecentResults<DesignKey, DesignResult> recent_{2};
  /// While result_ is provisional: the design and result before that edit (restored when the
  /// equilibration's completion fails).
  struct Before {
    StressDesign design;
    DesignResult result;
  };
  std::unique_ptr<Before> before_provisional_;
};

/// One-shot design (a StressDesigner without the edits).
DesignResult design_residual_stress(const TissueModel& model, const StressDesign& design);

}  // namespace cleave
