#include "measure_mechanics.hpp"

#include <algorithm>

#include "cleave/cut/body_surface.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/fem/solve_static.hpp"
#include "cleave/grid/vertices_only_of.hpp"
#include "implementation_setup.hpp"

namespace cleave::bench {
namespace {

Eigen::VectorXd flatten(const std::vector<Vec3>& per_vertex) {
  Eigen::VectorXd out(3 * static_cast<Eigen::Index>(per_vertex.size()));
  for (std::size_t v = 0; v < per_vertex.size(); ++v) out.segment<3>(3 * static_cast<Eigen::Index>(v)) = per_vertex[v];
  return out;
}

}  // namespace

MechanicsOutcome measure_incision_preview(const TissueModel& uncut, const BenchScenario& scenario,
                                          Implementation implementation, int repeat) {
  TissueModel model = uncut;
  StaticOptions options;
  {
    const BodySurface surface(model);
    const CutPlan plan = plan_cuts(surface, scenario.incisions);
    apply_cut_plan(model.volume, plan);
    options.fixed_vertices = vertices_only_of(model.volume, plan.hidden_cells());  // removed plugs, as in the studio
  }
  const SparseMatrix stiffness = assemble_stiffness(model);
  const ImplementationScope scope(implementation);
  options.solver = scope.solver();
  options.settings.parallel_substitution = scope.parallel_substitution();
  MechanicsOutcome out;
  std::vector<double> samples_ms;
  StaticResult result;
  for (int i = 0; i < std::max(repeat, 1); ++i)
    samples_ms.push_back(wall_time_ms([&] { result = solve_static(model, stiffness, scenario.residual_stress_kPa, options); }));
  out.figures.time = summarize_timings(samples_ms);
  out.figures.iterations = result.report.iterations;
  out.displacement_mm = flatten(result.displacement_mm);
  out.solver = result.solver_name;
  out.matrix_nonzeros = stiffness.nonZeros();
  return out;
}

MechanicsOutcome measure_dynamic_step(const TissueModel& uncut, const BenchScenario& scenario,
                                      Implementation implementation, int repeat, int iterations_per_step) {
  TissueModel model = uncut;
  const BodySurface surface(model);
  std::vector<CutPlan> segments;
  for (const ScalpelCut& cut : scenario.cut_segments) {
    CutRequests request;
    request.scalpel_cuts.push_back(cut);
    segments.push_back(plan_cuts(surface, request));
  }
  const ImplementationScope scope(implementation);
  DynamicsSettings settings;
  settings.solver = scope.solver();
  settings.solve.parallel_substitution = scope.parallel_substitution();
  settings.mass_damping_per_s = kBenchMassDamping_per_s;
  settings.iterations_per_step = iterations_per_step;
  Dynamics sim(model, scenario.residual_stress_kPa, settings);
  MechanicsOutcome out;
  std::vector<double> samples_ms;
  const int steps = kWarmUpSteps + std::max(repeat, 1);
  for (int i = 0; i < steps; ++i) {
    if (!segments.empty()) {
      const CutPlan& segment = segments[static_cast<std::size_t>(i) % segments.size()];
      sim.topology_changed(apply_cut_plan(model.volume, segment));
    }
    SolveReport report;
    const double ms = wall_time_ms([&] { report = sim.step(kBenchTimeStep_s); });
    if (i >= kWarmUpSteps) {
      samples_ms.push_back(ms);
      out.figures.iterations = std::max(out.figures.iterations, report.iterations);
    }
  }
  out.figures.time = summarize_timings(samples_ms);
  out.displacement_mm = sim.displacement();
  out.solver = std::string(sim.solver_name());
  return out;
}

}  // namespace cleave::bench
