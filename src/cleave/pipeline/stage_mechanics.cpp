#include <fmt/format.h>

#include "cleave/core/units.hpp"
#include "cleave/fem/cell_stress.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/solve_static.hpp"
#include "cleave/io/case_mechanics.hpp"
#include "cleave/pipeline/held_vertices.hpp"
#include "cleave/pipeline/stages.hpp"

namespace cleave {
namespace {

DataArray vector_array(const std::string& name, std::span<const Vec3> values) {
  DataArray a{name, 3, {}};
  a.values.reserve(3 * values.size());
  for (const Vec3& x : values) a.values.insert(a.values.end(), {x.x(), x.y(), x.z()});
  return a;
}

/// Voigt stresses in kPa written as Pa (the VTU unit).
DataArray stress_array_Pa(const std::string& name, std::span<const Vec6> stress_kPa) {
  DataArray a{name, 6, {}};
  a.values.reserve(6 * stress_kPa.size());
  for (const Vec6& s : stress_kPa)
    for (int i = 0; i < 6; ++i) a.values.push_back(s[i] * units::Pa_per_kPa);
  return a;
}

DataArray fixed_array(VertexId vertices, std::span<const VertexId> held) {
  DataArray a{"fixed", 1, std::vector<double>(static_cast<std::size_t>(vertices), 0.0)};
  for (const VertexId v : held) a.values[static_cast<std::size_t>(v)] = 1.0;
  return a;
}

double max_norm(std::span<const Vec3> values) {
  double m = 0;
  for (const Vec3& x : values) m = std::max(m, x.norm());
  return m;
}

}  // namespace

void stage_mechanics(RunContext& ctx) {
  const SimulationSettings settings = parse_simulation_settings(ctx.case_file);
  const LinkedVolume& volume = ctx.model.volume;
  if (ctx.residual_stress_kPa.empty())
    if (auto direct = parse_direct_residual_stress(ctx.case_file, ctx.model)) ctx.residual_stress_kPa = std::move(*direct);
  // The supports, and the removed plugs of round incisions (hidden, touching nothing).
  const std::vector<VertexId> held = held_vertices(ctx.model, settings, ctx.removed_cells);
  const bool loaded = !ctx.residual_stress_kPa.empty() || !settings.gravity_mm_per_s2.isZero();
  nlohmann::json summary = {{"mode", settings.mode == SimulationMode::dynamic ? "dynamic" : "static"},
                            {"fixed_vertices", held.size()},
                            {"held_removed_cells", ctx.removed_cells.size()}};

  ctx.displacement_mm.assign(static_cast<std::size_t>(volume.vertex_count()), Vec3::Zero());
  if (!loaded) {
    summary["solver"] = "none (no residual stress and no load: the body stays at rest)";
    summary["iterations"] = 0;
    summary["relative_residual"] = 0.0;
  } else if (settings.mode == SimulationMode::static_equilibrium) {
    StaticOptions options;
    options.solver = settings.solver;
    options.settings = settings.solve;
    options.fixed_vertices = held;
    if (!settings.gravity_mm_per_s2.isZero()) {
      const Vector mass = lumped_mass(ctx.model);
      options.external_force_mN = Vector::Zero(mass.size());
      for (Eigen::Index i = 0; i < mass.size(); ++i) options.external_force_mN[i] = mass[i] * settings.gravity_mm_per_s2[i % 3];
    }
    const StaticResult r = solve_static(ctx.model, ctx.residual_stress_kPa, options);
    ctx.displacement_mm = r.displacement_mm;
    summary["solver"] = r.solver_name;
    summary["iterations"] = r.report.iterations;
    summary["relative_residual"] = r.report.relative_residual;
    summary["free_components"] = r.free_components;
  } else {
    DynamicsSettings ds;
    ds.solver = settings.solver;
    ds.solve = settings.solve;
    ds.iterations_per_step = settings.iterations_per_step;
    ds.mass_damping_per_s = settings.mass_damping_per_s;
    ds.stiffness_damping_s = settings.stiffness_damping_s;
    ds.numerical_damping = settings.numerical_damping;
    ds.high_frequency_radius = settings.high_frequency_radius;
    ds.fixed_vertices = held;
    ds.gravity_mm_per_s2 = settings.gravity_mm_per_s2;
    Dynamics sim(ctx.model, ctx.residual_stress_kPa, ds);
    const int steps_per_file = settings.steps_per_frame * settings.frames_every;
    const auto write_frame = [&](int index) {
      const std::string name = fmt::format("frame_{:04d}.vtu", index);
      VolumeFields frame;
      const std::vector<Vec3> u = sim.displacement_mm();
      frame.point_data.push_back(vector_array("displacement", u));
      frame.point_data.push_back(fixed_array(volume.vertex_count(), held));
      write_vtu(ctx.out_dir / name, volume, frame);
      ctx.frames.push_back(PvdEntry{sim.time_s(), name});
      ctx.summary["files"].push_back((ctx.out_dir / name).string());
    };
    int frame_files = 0;
    if (steps_per_file > 0) write_frame(frame_files++);
    int total_iterations = 0;
    double worst_residual = 0;
    for (int step = 1; step <= settings.steps; ++step) {
      const SolveReport r = sim.step(settings.time_step_s);
      total_iterations += r.iterations;
      worst_residual = std::max(worst_residual, r.relative_residual);
      if (steps_per_file > 0 && step % steps_per_file == 0) write_frame(frame_files++);
      if (step % settings.steps_per_frame == 0) report(ctx.progress, "mechanics", static_cast<double>(step) / settings.steps);
    }
    ctx.displacement_mm = sim.displacement_mm();
    summary["solver"] = std::string(sim.solver_name());
    summary["iterations"] = total_iterations;
    summary["iterations_per_step"] = static_cast<double>(total_iterations) / settings.steps;
    summary["relative_residual"] = worst_residual;
    summary["steps"] = settings.steps;
    summary["time_step_s"] = settings.time_step_s;
    summary["end_time_s"] = sim.time_s();
    summary["frames_written"] = frame_files;
    summary["kinetic_energy_uJ"] = sim.kinetic_energy_uJ();
  }
  summary["max_displacement_mm"] = max_norm(ctx.displacement_mm);

  ctx.fields.point_data.push_back(vector_array("displacement", ctx.displacement_mm));
  ctx.fields.point_data.push_back(fixed_array(volume.vertex_count(), held));
  const std::vector<Vec6> residual =
      ctx.residual_stress_kPa.empty() ? std::vector<Vec6>(static_cast<std::size_t>(volume.cell_count()), Vec6::Zero())
                                      : ctx.residual_stress_kPa;
  ctx.fields.cell_data.push_back(stress_array_Pa("residual_stress", residual));
  ctx.fields.cell_data.push_back(stress_array_Pa("stress", total_cell_stress_kPa(ctx.model, residual, ctx.displacement_mm)));
  ctx.summary["mechanics"] = summary;
}

}  // namespace cleave
