#pragma once
// The design stages and the edit-to-picture update, timed on the uncut model for one
// implementation. Every implementation makes the same `repeat` edits: stroke 0 alternates
// between the scenario's edited stroke and its original, so each edit is a real change and the
// final design is the same for all.
//
//   cleave  StressDesigner (sparse Cholesky, symbolic analysis reused, normals cached) after each
//           edit: vector = its directions time, value = eigenvalues, equilibrate = equilibration.
//           update = the whole edit as the studio does it: the designer's update, the incision
//           preview solve with the new stress on the incised body (stiffness assembled once,
//           cut topology unchanged by a stroke edit) and the deformed render surface.
//   paper   one thread; vector = PaperDirections (plain CG, Langer and normal fields, warm
//           started), value = StressDesigner with EigenvalueSolver::paper_cg (the stress
//           engineer's reference: CG on A^T A, warm-started); equilibrate is not the paper's.
//   others  Eigen CG and CHOLMOD do not apply to the design stages by themselves: cleave's design
//           already uses CHOLMOD (recorded as skipped with that reason).
//
// Results for agreement: the frames' line tensors and the eigenvalues after the last edit.
#include "bench_figures.hpp"
#include "bench_scenario.hpp"

namespace cleave::bench {

struct DesignOutcome {
  StageFigures vector, value, equilibrate, update;
  Eigen::VectorXd line_tensors;  ///< frame_line_tensors of the final frames
  Eigen::VectorXd eigenvalues_kPa;  ///< 3 per cell (Langer, cross, normal)
};

DesignOutcome measure_design(const TissueModel& uncut, const BenchScenario& scenario, Implementation implementation,
                             int repeat);

}  // namespace cleave::bench
