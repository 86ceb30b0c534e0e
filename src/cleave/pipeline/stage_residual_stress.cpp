// Stage "residual stress" of a batch run: the case's "residual_stress" section (given directly,
// io/case_mechanics.hpp) or its "design" section (strokes and control points, io/case_design.hpp,
// stress/stress_designer.hpp). A design adds the cell fields langer_direction, normal_direction
// (unit vectors) and eigenvalues (Langer, cross, normal in Pa), writes streamlines.vtp when
// output.streamlines is on, and reports summary["design"]: the relative equilibrium residual
// before and after equilibration and the time of each step. With "equilibrium_support":
// "simulation" the vertices held by the "simulation" section are left out of the equilibrium.
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/core/units.hpp"
#include "cleave/io/case_design.hpp"
#include "cleave/io/case_mechanics.hpp"
#include "cleave/io/vtp_writer.hpp"
#include "cleave/pipeline/held_vertices.hpp"
#include "cleave/pipeline/stages.hpp"
#include "cleave/stress/stress_designer.hpp"
#include "cleave/viz/streamlines.hpp"

namespace cleave {
namespace {

DataArray direction_array(const std::string& name, const std::vector<DirectionFrame>& frames, Vec3 DirectionFrame::*member) {
  DataArray a{name, 3, {}};
  a.values.reserve(3 * frames.size());
  for (const DirectionFrame& f : frames)
    for (int i = 0; i < 3; ++i) a.values.push_back((f.*member)[i]);
  return a;
}

DataArray eigenvalue_array(const std::vector<Vec3>& eigenvalues_kPa) {
  DataArray a{"eigenvalues", 3, {}};
  a.values.reserve(3 * eigenvalues_kPa.size());
  for (const Vec3& l : eigenvalues_kPa)
    for (int i = 0; i < 3; ++i) a.values.push_back(l[i] * units::Pa_per_kPa);
  return a;
}

void run_design(RunContext& ctx, StressDesign design) {
  if (design.support == EquilibriumSupport::simulation) design.held_vertices = held_vertices(ctx.model, parse_simulation_settings(ctx.case_file));
  DesignResult result;
  try {
    result = design_residual_stress(ctx.model, design);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", ctx.case_file.at("design").str(), e.what()));
  }
  ctx.residual_stress_kPa = result.stress_kPa;
  ctx.fields.cell_data.push_back(direction_array("langer_direction", result.frames, &DirectionFrame::langer));
  ctx.fields.cell_data.push_back(direction_array("normal_direction", result.frames, &DirectionFrame::normal));
  ctx.fields.cell_data.push_back(eigenvalue_array(result.eigenvalues_kPa));

  nlohmann::json summary = {
      {"strokes", design.strokes.size()},
      {"control_points", design.control_points.size()},
      {"solver", design.solver == EigenvalueSolver::cholesky ? "default" : "paper-cg"},
      {"equilibrated", design.equilibration == Equilibration::growth},
      {"equilibrium_support", design.support == EquilibriumSupport::simulation ? "simulation" : "none"},
      {"held_vertices", design.held_vertices.size()},
      {"equilibrium_residual_designed", result.residual_designed},
      {"equilibrium_residual_final", result.residual_final},
      {"equilibrium_residual_definition",
       "||T sigma|| / (||T||_2 ||sigma||) over the free vertices (all unless equilibrium_support is simulation), ||T||_2 by "
       "power iteration"},
      {"eigenvalue_iterations", result.eigenvalue_iterations},
      {"timings_s",
       {{"directions", result.timings.directions_s},
        {"eigenvalues", result.timings.eigenvalues_s},
        {"equilibration", result.timings.equilibration_s}}}};
  if (ctx.case_file.output.streamlines) {
    Polylines lines;
    lines.lines = trace_streamlines(ctx.model.volume, result.frames);
    const std::filesystem::path file = ctx.out_dir / "streamlines.vtp";
    write_vtp_polylines(file, lines);
    summary["streamlines"] = lines.lines.size();
    if (!ctx.summary.contains("files")) ctx.summary["files"] = nlohmann::json::array();
    ctx.summary["files"].push_back(file.string());
  }
  ctx.summary["design"] = std::move(summary);
}

}  // namespace

void stage_residual_stress(RunContext& ctx) {
  const std::optional<StressDesign> design = parse_case_design(ctx.case_file);
  const bool direct = ctx.case_file.section("residual_stress") != nullptr;
  if (design && direct)
    throw InputError(fmt::format("{}: has both \"design\" and \"residual_stress\"; expected one of them",
                                 ctx.case_file.path.filename().string()));
  if (design) {
    run_design(ctx, *design);
  } else if (direct) {
    if (auto stress = parse_direct_residual_stress(ctx.case_file, ctx.model)) ctx.residual_stress_kPa = std::move(*stress);
  }
}

}  // namespace cleave
