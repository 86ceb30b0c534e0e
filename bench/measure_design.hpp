#pragma once
// The design stages and the edit-to-picture update, timed on the uncut model for one
// implementation, on the scenario design's weights (`cleave bench --design-equilibrium` sets w_E).
// Every implementation makes the same edits:
//   stroke edits          `repeat` times: stroke 0 alternates between the scenario's edited stroke
//                         and its original, so each edit is a real change;
//   a drag                then stroke 0 over fresh cells, one cell further at every edit (the
//                         scenario's dragged strokes), then back to where the stroke edits left it;
//   control-point edits   then `repeat` times, in turn: add a control point (at the middle of the
//                         edited stroke, Langer 25 / cross 15 kPa), move it (to the middle of the
//                         original stroke 0), delete it;
// so the final design is the same for all and their eigenvalues are compared.
//
//   cleave  StressDesigner (sparse Cholesky, symbolic analysis reused, factor kept, normals
//           cached) after each edit: vector = its directions time, value = eigenvalues after a
//           stroke edit (0: not redone when w_E = 0), value_point = eigenvalues after a control
//           point edit, equilibrate = equilibration after a stroke edit.
//           update = the whole stroke edit as the studio does it: the designer's update, the
//           incision preview solve with the new stress on the incised body (stiffness assembled
//           once, cut topology unchanged by a stroke edit) and the deformed render surface.
//           The picture is drawn from the equilibration's provisional stress when it has one
//           (EquilibrationPass::picture, as the studio draws it); the completion after the
//           picture is timed apart: update_final = update + completion.
//           vector_drag / update_drag / update_drag_final: the same for the drag's edits.
//   paper   one thread; vector = PaperDirections (plain CG, Langer and normal fields, warm
//           started), value / value_point = StressDesigner with EigenvalueSolver::paper_cg (the
//           paper's CG on A^T A, warm-started from the previous eigenvalues); equilibrate is not
//           the paper's; vector_drag = PaperDirections for the drag's edits.
//   others  Eigen CG and CHOLMOD do not apply to the design stages by themselves: cleave's design
//           already uses CHOLMOD (recorded as skipped with that reason).
//
// Results for agreement: the frames' line tensors after the last stroke edit and the
// eigenvalues after the last edit.
#include "bench_figures.hpp"
#include "bench_scenario.hpp"

namespace cleave::bench {

struct DesignOutcome {
  StageFigures vector, value, value_point, equilibrate, update, vector_drag, update_drag, update_final, update_drag_final;
  Eigen::VectorXd line_tensors;  ///< frame_line_tensors of the final frames
  Eigen::VectorXd eigenvalues_kPa;  ///< 3 per cell (Langer, cross, normal)
};

DesignOutcome measure_design(const TissueModel& uncut, const BenchScenario& scenario, Implementation implementation,
                             int repeat);

}  // namespace cleave::bench
