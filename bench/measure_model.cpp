#include "measure_model.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cleave/core/error.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "implementation_setup.hpp"
#include "measure_design.hpp"
#include "measure_mechanics.hpp"
#include "peak_memory.hpp"

namespace cleave::bench {
namespace {

/// What one implementation produced on one model, kept to compare the peers with cleave.
struct ImplementationResults {
  ImplementationFigures figures;
  Eigen::VectorXd preview_mm;
  Eigen::VectorXd step_mm;
  Eigen::VectorXd line_tensors;
  Eigen::VectorXd eigenvalues_kPa;
  std::int64_t stiffness_nonzeros = 0;
};

constexpr double kMeasuredDesignPeakGb = 4.2;       // tube-42 / cylinder-42, default design
constexpr double kMeasuredDesignPeakCells = 44'064.0;
constexpr double kNestedDissectionFillExponent = 4.0 / 3.0;

ImplementationResults run_implementation(const TissueModel& model, const BenchScenario& scenario,
                                         Implementation implementation, const BenchOptions& options,
                                         const std::string& design_skipped, const ProgressFn& progress, double done,
                                         double share) {
  ImplementationResults r;
  r.figures.implementation = implementation;
  reset_peak_resident_memory();
  const std::string who(implementation_key(implementation));
  if (design_skipped.empty()) {
    report(progress, who + ": design", done);
    DesignOutcome design = measure_design(model, scenario, implementation, options.repeat);
    r.figures.vector = design.vector;
    r.figures.value = design.value;
    r.figures.value_point = design.value_point;
    r.figures.equilibrate = design.equilibrate;
    r.figures.update = design.update;
    r.figures.vector_drag = design.vector_drag;
    r.figures.update_drag = design.update_drag;
    r.figures.update_final = design.update_final;
    r.figures.update_drag_final = design.update_drag_final;
    r.line_tensors = std::move(design.line_tensors);
    r.eigenvalues_kPa = std::move(design.eigenvalues_kPa);
  } else {
    for (StageFigures* s : {&r.figures.vector, &r.figures.value, &r.figures.value_point, &r.figures.equilibrate, &r.figures.update,
                            &r.figures.vector_drag, &r.figures.update_drag, &r.figures.update_final, &r.figures.update_drag_final})
      s->skipped = design_skipped;
  }
  report(progress, who + ": incision preview", done + 0.4 * share);
  MechanicsOutcome preview = measure_incision_preview(model, scenario, implementation, options.repeat);
  report(progress, who + ": dynamic step", done + 0.7 * share);
  MechanicsOutcome step = measure_dynamic_step(model, scenario, implementation, options.repeat);
  r.figures.preview = preview.figures;
  r.figures.step = step.figures;
  if (implementation == Implementation::cleave) {
    report(progress, who + ": dynamic step with the real-time budget", done + 0.85 * share);
    const MechanicsOutcome budget = measure_dynamic_step(model, scenario, implementation, options.repeat, kRealTimeIterationsPerStep);
    r.figures.step_budget = budget.figures;
    r.figures.step_budget.relative_difference = relative_difference(budget.displacement_mm, step.displacement_mm);
  } else {
    r.figures.step_budget.skipped = "the real-time budget is cleave's; the peers solve every step";
  }
  r.figures.solver = preview.solver;
  r.stiffness_nonzeros = preview.matrix_nonzeros;
  r.preview_mm = std::move(preview.displacement_mm);
  r.step_mm = std::move(step.displacement_mm);
  r.figures.peak_mb = peak_resident_memory_mb();
  return r;
}

/// A peer's edit-to-picture update: the sum of the medians of its own design and preview stages,
/// with cleave's where the peer has none (the peers run no studio pipeline of their own).
StageFigures composite_update(const ImplementationFigures& cleave, const ImplementationFigures& peer) {
  StageFigures update;
  double total_ms = 0;
  for (Stage s : {Stage::vector, Stage::value, Stage::equilibrate, Stage::preview}) {
    const StageFigures& own = peer.stage(s);
    total_ms += (own.time.count > 0 ? own : cleave.stage(s)).time.median_ms;
  }
  const double samples[] = {total_ms};
  update.time = summarize_timings(samples);
  update.iterations = peer.preview.iterations;
  return update;
}

void compare_with_cleave(const ImplementationResults& cleave, ImplementationResults& peer) {
  if (peer.line_tensors.size() > 0) peer.figures.vector.relative_difference = relative_difference(peer.line_tensors, cleave.line_tensors);
  if (peer.eigenvalues_kPa.size() > 0)
    peer.figures.value.relative_difference = peer.figures.value_point.relative_difference =
        relative_difference(peer.eigenvalues_kPa, cleave.eigenvalues_kPa);
  peer.figures.preview.relative_difference = relative_difference(peer.preview_mm, cleave.preview_mm);
  peer.figures.step.relative_difference = relative_difference(peer.step_mm, cleave.step_mm);
}

ImplementationFigures skipped(Implementation implementation, const std::string& why) {
  ImplementationFigures f;
  f.implementation = implementation;
  for (Stage s : kAllStages) f.stage(s).skipped = why;
  return f;
}

}  // namespace

double design_memory_estimate_gb(int cells) {
  return kMeasuredDesignPeakGb * std::pow(static_cast<double>(cells) / kMeasuredDesignPeakCells, kNestedDissectionFillExponent);
}

ModelFigures measure_model(const BenchModel& bench_model, const BenchOptions& options, const ProgressFn& progress) {
  const Vec3i& n = bench_model.cells;
  report(progress, fmt::format("{}: building the {}x{}x{} grid", bench_model.key, n.x(), n.y(), n.z()), 0.0);
  const TissueModel model =
      make_tissue_model(bench_model.shape, make_builtin_shape(bench_model.shape, {bench_model.cells, std::nullopt}));
  const int cells = model.volume.cell_count();
  // Decided before anything is allocated for the design: its factors grow faster than the cells.
  std::string design_skipped;
  if (cells > options.design_max_cells) {
    const double gb = design_memory_estimate_gb(cells);
    design_skipped = fmt::format("design factor would need ~{} GB ({} cells is above --design-max-cells {})",
                                 gb < 10 ? fmt::format("{:.1f}", gb) : fmt::format("{:.0f}", gb), cells, options.design_max_cells);
  }
  ScenarioOptions scenario_options;
  scenario_options.cut_segments = kWarmUpSteps + std::max(options.repeat, 1);
  scenario_options.designed_stress = design_skipped.empty();
  report(progress,
         fmt::format("{}: {} cells, scenario ({} residual stress)", bench_model.key, cells,
                     design_skipped.empty() ? "designed" : "prescribed 20/10 kPa"),
         0.0);
  BenchScenario scenario = make_bench_scenario(model, scenario_options);
  if (options.design_equilibrium_weight) scenario.design.weights.equilibrium = *options.design_equilibrium_weight;

  ModelFigures figures;
  figures.model = bench_model;
  figures.cells = model.volume.cell_count();
  figures.vertices = model.volume.vertex_count();
  figures.incisions = static_cast<int>(scenario.incisions.incisions.size());
  figures.design_equilibrium_weight = scenario.design.weights.equilibrium;
  figures.residual_stress = scenario.designed_stress ? "design" : "prescribed";

  const double share = 1.0 / static_cast<double>(1 + options.peers.size());
  const ImplementationResults cleave =
      run_implementation(model, scenario, Implementation::cleave, options, design_skipped, progress, 0.0, share);
  figures.cleave = cleave.figures;
  figures.stiffness_nonzeros = cleave.stiffness_nonzeros;
  for (std::size_t i = 0; i < options.peers.size(); ++i) {
    const Implementation peer = options.peers[i];
    if (figures.cells > options.peer_max_cells) {
      figures.peers.push_back(skipped(peer, fmt::format("{} cells is above --peer-max-cells {}", figures.cells, options.peer_max_cells)));
      continue;
    }
    ImplementationResults r;
    try {
      r = run_implementation(model, scenario, peer, options, design_skipped, progress, share * static_cast<double>(i + 1), share);
    } catch (const ComputeError& e) {  // a peer that fails (e.g. Eigen CG out of iterations) is reported, not fatal
      figures.peers.push_back(skipped(peer, fmt::format("failed: {}", e.what())));
      continue;
    }
    compare_with_cleave(cleave, r);
    if (design_skipped.empty()) r.figures.update = composite_update(cleave.figures, r.figures);
    figures.peers.push_back(std::move(r.figures));
  }
  report(progress, fmt::format("{}: done", bench_model.key), 1.0);
  return figures;
}

}  // namespace cleave::bench
