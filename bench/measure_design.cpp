#include "measure_design.hpp"

#include <algorithm>

#include "cleave/cut/body_surface.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/static_solver.hpp"
#include "cleave/grid/vertices_only_of.hpp"
#include "cleave/stress/stress_designer.hpp"
#include "cleave/surface/render_surface.hpp"
#include "implementation_setup.hpp"
#include "paper_reference_directions.hpp"

namespace cleave::bench {
namespace {

constexpr double kMsPerSecond = 1e3;

/// Stroke 0 of update edit number `edit`: the two edited positions and the design's own in turn.
DesignStroke stroke_of_edit(const BenchScenario& scenario, int edit) {
  const auto turn = static_cast<std::size_t>(edit % 3);
  return turn < scenario.edited_strokes.size() ? scenario.edited_strokes[turn] : scenario.design.strokes.front();
}

DesignControlPoint middle_of(const DesignStroke& stroke) {
  return {stroke.points_mm[stroke.points_mm.size() / 2], 25.0, 15.0};
}

/// Control-point edit number `edit`: add, move, delete in turn (the added point is the last one).
void control_point_edit(StressDesigner& designer, const BenchScenario& scenario, int edit) {
  switch (edit % 3) {
    case 0: designer.add_control_point(middle_of(scenario.edited_strokes.front())); break;
    case 1:
      designer.move_control_point(designer.design().control_points.size() - 1, middle_of(scenario.design.strokes.front()));
      break;
    default: designer.delete_control_point(designer.design().control_points.size() - 1); break;
  }
}

/// Times `repeat` control-point edits (ms of the eigenvalue stage of each).
std::vector<double> time_control_point_edits(StressDesigner& designer, const BenchScenario& scenario, int repeat) {
  std::vector<double> value_ms;
  for (int edit = 0; edit < repeat; ++edit) {
    control_point_edit(designer, scenario, edit);
    value_ms.push_back(kMsPerSecond * designer.result().timings.eigenvalues_s);
  }
  return value_ms;
}

Eigen::VectorXd flatten_eigenvalues(const std::vector<Vec3>& eigenvalues_kPa) {
  Eigen::VectorXd out(3 * static_cast<Eigen::Index>(eigenvalues_kPa.size()));
  for (std::size_t c = 0; c < eigenvalues_kPa.size(); ++c) out.segment<3>(3 * static_cast<Eigen::Index>(c)) = eigenvalues_kPa[c];
  return out;
}

/// The incised body the preview shows, with what a stroke edit leaves unchanged.
struct IncisedPreview {
  TissueModel model;
  SparseMatrix stiffness;
  RenderSurface surface;
  std::vector<VertexId> held;  ///< the removed plugs' vertices, held as the studio holds them
};

IncisedPreview incised_preview(const TissueModel& uncut, const BenchScenario& scenario) {
  IncisedPreview p{uncut, {}, {}, {}};
  {
    const BodySurface body(p.model);
    const CutPlan plan = plan_cuts(body, scenario.incisions);
    apply_cut_plan(p.model.volume, plan);
    p.held = vertices_only_of(p.model.volume, plan.hidden_cells());
  }
  SparseMatrix stiffness = assemble_stiffness(p.model);
  p.stiffness.swap(stiffness);  // Eigen 3.4's SparseMatrix has no move assignment
  p.surface = build_render_surface(p.model);
  return p;
}

DesignOutcome measure_cleave(const TissueModel& uncut, const BenchScenario& scenario, int repeat) {
  const IncisedPreview preview = incised_preview(uncut, scenario);
  StressDesigner designer(uncut, scenario.design);
  std::vector<double> vector_ms, value_ms, equilibrate_ms, update_ms;
  int preview_iterations = 0;
  int equilibrate_iterations = 0;  ///< the most of any edit
  std::vector<Vec3> picture_mm;  // deformed render surface vertices: what the page draws
  // The preview's statics are kept across edits as the studio keeps them: CHOLMOD's factor of the
  // incised body (removed plugs held), made at the first edit's solve, then one forward/back
  // substitution per edit with its single-precision copy, to the picture's tolerance
  // (preview_static_options).
  StaticSolver statics(preview.model, preview.stiffness, preview_static_options(preview.held));
  // The picture, then the equilibration's completion (ms of each).
  const auto stroke_edit = [&](const DesignStroke& stroke) {
    const double picture_ms = wall_time_ms([&] {
      StressDesign moved = designer.design();
      moved.strokes.front() = stroke;
      designer.set_design(std::move(moved), EquilibrationPass::picture);
      const StaticResult solved = statics.solve(designer.result().stress_kPa);
      picture_mm = deformed_positions(preview.surface, preview.model.volume, solved.displacement_mm);
      preview_iterations = solved.report.iterations;
    });
    const double completion_ms = wall_time_ms([&] { designer.finish_equilibration(); });
    return std::pair{picture_ms, picture_ms + completion_ms};
  };
  std::vector<double> final_ms;
  for (int edit = 0; edit < repeat; ++edit) {
    const auto [picture_ms, done_ms] = stroke_edit(stroke_of_edit(scenario, edit));
    update_ms.push_back(picture_ms);
    final_ms.push_back(done_ms);
    const DesignTimings& t = designer.result().timings;
    vector_ms.push_back(kMsPerSecond * t.directions_s);
    value_ms.push_back(kMsPerSecond * t.eigenvalues_s);
    equilibrate_ms.push_back(kMsPerSecond * t.equilibration_s);
    equilibrate_iterations = std::max(equilibrate_iterations, designer.result().equilibration_iterations);
  }
  std::vector<double> drag_vector_ms, drag_update_ms, drag_final_ms;
  for (const DesignStroke& stroke : scenario.dragged_strokes) {
    const auto [picture_ms, done_ms] = stroke_edit(stroke);
    drag_update_ms.push_back(picture_ms);
    drag_final_ms.push_back(done_ms);
    drag_vector_ms.push_back(kMsPerSecond * designer.result().timings.directions_s);
  }
  designer.move_stroke(0, stroke_of_edit(scenario, repeat - 1));
  DesignOutcome out;
  out.line_tensors = frame_line_tensors(designer.result().frames);
  out.vector_drag.time = summarize_timings(drag_vector_ms);
  out.update_drag.time = summarize_timings(drag_update_ms);
  out.update_drag.iterations = preview_iterations;
  out.update_drag_final.time = summarize_timings(drag_final_ms);
  out.update_drag_final.iterations = preview_iterations;
  out.vector.time = summarize_timings(vector_ms);
  out.value.time = summarize_timings(value_ms);
  out.value.iterations = designer.result().eigenvalue_iterations;
  out.value_point.time = summarize_timings(time_control_point_edits(designer, scenario, repeat));
  out.value_point.iterations = designer.result().eigenvalue_iterations;
  out.equilibrate.time = summarize_timings(equilibrate_ms);
  out.equilibrate.iterations = equilibrate_iterations;
  out.update.time = summarize_timings(update_ms);
  out.update.iterations = preview_iterations;
  out.update_final.time = summarize_timings(final_ms);
  out.update_final.iterations = preview_iterations;
  out.eigenvalues_kPa = flatten_eigenvalues(designer.result().eigenvalues_kPa);
  return out;
}

DesignOutcome measure_paper(const TissueModel& uncut, const BenchScenario& scenario, int repeat) {
  const ImplementationScope one_thread(Implementation::paper);
  StressDesign design = scenario.design;
  design.solver = EigenvalueSolver::paper_cg;
  StressDesigner designer(uncut, design);
  PaperDirections directions(uncut, design);
  directions.interpolate(design.strokes);  // the paper's fields of the initial design: the warm start
  std::vector<double> vector_ms, value_ms;
  PaperDirectionResult paper_frames;
  for (int edit = 0; edit < repeat; ++edit) {
    std::vector<DesignStroke> strokes = design.strokes;
    strokes.front() = stroke_of_edit(scenario, edit);
    vector_ms.push_back(wall_time_ms([&] { paper_frames = directions.interpolate(strokes); }));
    designer.move_stroke(0, strokes.front());
    value_ms.push_back(kMsPerSecond * designer.result().timings.eigenvalues_s);
  }
  std::vector<double> drag_vector_ms;
  for (const DesignStroke& stroke : scenario.dragged_strokes) {
    std::vector<DesignStroke> strokes = design.strokes;
    strokes.front() = stroke;
    drag_vector_ms.push_back(wall_time_ms([&] { directions.interpolate(strokes); }));
  }
  DesignOutcome out;
  out.vector_drag.time = summarize_timings(drag_vector_ms);
  out.update_drag.skipped = out.update_final.skipped = out.update_drag_final.skipped =
      "the paper's pipeline has no edit-to-picture update";
  out.vector.time = summarize_timings(vector_ms);
  out.vector.iterations = paper_frames.iterations;
  out.value.time = summarize_timings(value_ms);
  out.value.iterations = designer.result().eigenvalue_iterations;
  out.value_point.time = summarize_timings(time_control_point_edits(designer, scenario, repeat));
  out.value_point.iterations = designer.result().eigenvalue_iterations;
  out.equilibrate.skipped = "the paper has no equilibration step";
  out.line_tensors = frame_line_tensors(paper_frames.frames);
  out.eigenvalues_kPa = flatten_eigenvalues(designer.result().eigenvalues_kPa);
  return out;
}

}  // namespace

DesignOutcome measure_design(const TissueModel& uncut, const BenchScenario& scenario, Implementation implementation,
                             int repeat) {
  repeat = std::max(repeat, 1);
  switch (implementation) {
    case Implementation::cleave: return measure_cleave(uncut, scenario, repeat);
    case Implementation::paper: return measure_paper(uncut, scenario, repeat);
    case Implementation::eigen_cg:
    case Implementation::cholmod: break;
  }
  DesignOutcome out;
  const std::string why = "cleave's design stages already use CHOLMOD (supernodal, analysis reused)";
  out.vector.skipped = out.value.skipped = out.value_point.skipped = out.equilibrate.skipped = out.vector_drag.skipped =
      out.update_drag.skipped = out.update_final.skipped = out.update_drag_final.skipped = why;
  return out;
}

}  // namespace cleave::bench
