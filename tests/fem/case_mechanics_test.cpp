// The case sections "simulation" and "residual_stress", and the mechanics stage end to end on a
// small model: exact error messages for bad input, and released stress on a free body.
#include <gtest/gtest.h>

#include <filesystem>

#include "cleave/core/error.hpp"
#include "cleave/io/case_mechanics.hpp"
#include "cleave/pipeline/stages.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

CaseFile case_from(const std::string& sections) {
  return parse_case_text("{\"model\": {\"source\": \"plate\"}" + sections + "}", "case.json", ".");
}

std::string simulation_error(const std::string& section) {
  try {
    parse_simulation_settings(case_from(", \"simulation\": " + section));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string case_error(const std::string& sections) {
  try {
    case_from(sections);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string stress_error(const std::string& section) {
  const TissueModel model = test::make_box_model({2, 2, 1}, 1.0);
  try {
    parse_direct_residual_stress(case_from(", \"residual_stress\": " + section), model);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CaseMechanics, SimulationSettingsAreReadWithDefaults) {
  const SimulationSettings defaults = parse_simulation_settings(case_from(""));
  EXPECT_EQ(defaults.mode, SimulationMode::static_equilibrium);
  EXPECT_EQ(defaults.solver, SolverKind::multigrid_cg);
  EXPECT_TRUE(defaults.fixed_boxes.empty());
  EXPECT_EQ(defaults.numerical_damping, 0.2);
  const SimulationSettings s = parse_simulation_settings(case_from(
      R"(, "simulation": {"mode": "dynamic", "solver": "cholmod", "tolerance": 1e-9, "time_step_s": 0.002, "steps": 50,
          "steps_per_frame": 5, "frames_every": 2, "iterations_per_step": 4, "damping": {"mass_per_s": 3, "stiffness_s": 0.01, "numerical": 0, "high_frequency_radius": 0.25},
          "fixed": [{"box_mm": [[0, 0, 0], [1, 100, 10]]}], "gravity_mm_per_s2": [0, 0, -9810]})"));
  EXPECT_EQ(s.mode, SimulationMode::dynamic);
  EXPECT_EQ(s.solver, SolverKind::cholmod);
  EXPECT_EQ(s.solve.relative_tolerance, 1e-9);
  EXPECT_EQ(s.time_step_s, 0.002);
  EXPECT_EQ(s.steps, 50);
  EXPECT_EQ(s.steps_per_frame, 5);
  EXPECT_EQ(s.frames_every, 2);
  EXPECT_EQ(s.iterations_per_step, 4);
  EXPECT_EQ(defaults.iterations_per_step, 0);
  EXPECT_EQ(s.mass_damping_per_s, 3.0);
  EXPECT_EQ(s.stiffness_damping_s, 0.01);
  EXPECT_EQ(s.numerical_damping, 0.0);
  EXPECT_EQ(s.high_frequency_radius, 0.25);
  EXPECT_FALSE(defaults.high_frequency_radius.has_value());  // HHT unless asked
  ASSERT_EQ(s.fixed_boxes.size(), 1u);
  EXPECT_EQ(s.fixed_boxes[0].hi_mm, Vec3(1, 100, 10));
  EXPECT_EQ(s.gravity_mm_per_s2, Vec3(0, 0, -9810));
}

TEST(CaseMechanics, BadSimulationFieldsAreNamed) {
  EXPECT_EQ(simulation_error(R"({"time_step_s": -1})"),
            "case.json: /simulation/time_step_s is -1; expected a positive time step in s");
  EXPECT_EQ(simulation_error(R"({"time_step_s": 0})"),
            "case.json: /simulation/time_step_s is 0; expected a positive time step in s");
  EXPECT_EQ(simulation_error(R"({"damping": {"numerical": 0.5}})"),
            "case.json: /simulation/damping/numerical is 0.5; expected a numerical damping (HHT -alpha) from 0 to 1/3");
  EXPECT_EQ(simulation_error(R"({"steps": 0})"), "case.json: /simulation/steps is 0; expected an integer from 1 to 100000000");
  EXPECT_EQ(simulation_error(R"({"mode": "quasi"})"), "case.json: /simulation/mode is \"quasi\"; expected \"static\" or \"dynamic\"");
  EXPECT_EQ(simulation_error(R"({"solver": "lu"})"),
            "case.json: /simulation/solver is \"lu\"; expected \"multigrid\", \"eigen-cg\" or \"cholmod\"");
  EXPECT_EQ(simulation_error(R"({"tolerance": 2})"),
            "case.json: /simulation/tolerance is 2; expected a relative residual tolerance in (0, 1)");
  EXPECT_EQ(simulation_error(R"({"damping": {"mass_per_s": -0.5}})"),
            "case.json: /simulation/damping/mass_per_s is -0.5; expected a non-negative mass damping in 1/s");
  EXPECT_EQ(simulation_error(R"({"fixed": {"box_mm": [[1, 0, 0], [0, 1, 1]]}})"),
            "case.json: /simulation/fixed/box_mm is [[1,0,0],[0,1,1]]; expected a lower corner [x0, y0, z0] not above the upper corner [x1, y1, z1]");
  EXPECT_EQ(simulation_error(R"({"fixed": "left"})"),
            "case.json: /simulation/fixed is \"left\"; expected \"none\", \"free\", {\"box_mm\": [[x0, y0, z0], [x1, y1, z1]]}, {\"surface\": \"inner\"} or an array of such");
  EXPECT_EQ(simulation_error(R"({"time_step": 0.1})"),
            "case.json: /simulation has unknown key 'time_step'; expected one of: mode, solver, tolerance, max_iterations, "
            "iterations_per_step, time_step_s, steps, steps_per_frame, frames_every, damping, fixed, gravity_mm_per_s2");
  EXPECT_EQ(simulation_error(R"({"iterations_per_step": -2})"),
            "case.json: /simulation/iterations_per_step is -2; expected an integer from 0 to 100000000");
  EXPECT_EQ(simulation_error(R"({"damping": {"high_frequency_radius": 1.5}})"),
            "case.json: /simulation/damping/high_frequency_radius is 1.5; expected a spectral radius from 0 to 1 (generalized-alpha)");
}

TEST(CaseMechanics, BadMaterialsAreNamed) {
  EXPECT_EQ(case_error(R"(, "materials": {"1": {"E_kPa": 0}})"),
            "case.json: /materials/1/E_kPa is 0; expected a positive Young's modulus in kPa");
  EXPECT_EQ(case_error(R"(, "materials": {"1": {"E_kPa": -80}})"),
            "case.json: /materials/1/E_kPa is -80; expected a positive Young's modulus in kPa");
  EXPECT_EQ(case_error(R"(, "materials": {"1": {"nu": 0.5}})"), "case.json: /materials/1/nu is 0.5; expected a Poisson ratio in (-1, 0.5)");
  EXPECT_EQ(case_error(R"(, "materials": {"1": {"nu": -1}})"), "case.json: /materials/1/nu is -1; expected a Poisson ratio in (-1, 0.5)");
  EXPECT_EQ(case_error(R"(, "materials": {"1": {"density_kg_per_m3": 0}})"),
            "case.json: /materials/1/density_kg_per_m3 is 0; expected a positive density in kg/m^3");
}

TEST(CaseMechanics, DirectResidualStressIsReadPerCell) {
  TissueModel model = test::make_box_model({2, 2, 2}, 1.0, 80.0, 0.4, [](const Vec3i& v) { return Label(v.z() == 0 ? 1 : 2); });
  const auto uniform = parse_direct_residual_stress(case_from(R"(, "residual_stress": {"uniform_kPa": [20, 10, 0, 1, 0, 0]})"), model);
  ASSERT_TRUE(uniform.has_value());
  ASSERT_EQ(uniform->size(), 8u);
  EXPECT_EQ((*uniform)[5], (Vec6() << 20, 10, 0, 1, 0, 0).finished());
  const auto per_label = parse_direct_residual_stress(case_from(R"(, "residual_stress": {"per_label_kPa": {"2": [5, 0, 0, 0, 0, 0]}})"), model);
  ASSERT_TRUE(per_label.has_value());
  for (CellId c = 0; c < model.volume.cell_count(); ++c)
    EXPECT_EQ((*per_label)[static_cast<std::size_t>(c)][0], model.volume.cell_label(c) == 2 ? 5.0 : 0.0);
  EXPECT_FALSE(parse_direct_residual_stress(case_from(""), model).has_value());
}

TEST(CaseMechanics, BadResidualStressIsNamed) {
  EXPECT_EQ(stress_error(R"({"uniform_kPa": [20, 10, "NaN", 0, 0, 0]})"),
            "case.json: /residual_stress/uniform_kPa/2 is \"NaN\"; expected a finite stress in kPa, at most 1e9 in magnitude");
  EXPECT_EQ(stress_error(R"({"uniform_kPa": [null, 10, 0, 0, 0, 0]})"),
            "case.json: /residual_stress/uniform_kPa/0 is null; expected a finite stress in kPa, at most 1e9 in magnitude");
  // Finite but beyond any material: the forces (stress x area) would overflow.
  EXPECT_EQ(stress_error(R"({"uniform_kPa": [20, 10, 0, -1e200, 0, 0]})"),
            "case.json: /residual_stress/uniform_kPa/3 is -1e+200; expected a finite stress in kPa, at most 1e9 in magnitude");
  EXPECT_EQ(stress_error(R"({"per_label_kPa": {"1": [2e9, 0, 0, 0, 0, 0]}})"),
            "case.json: /residual_stress/per_label_kPa/1/0 is 2000000000.0; expected a finite stress in kPa, at most 1e9 in magnitude");
  EXPECT_EQ(stress_error(R"({"uniform_kPa": [1e9, -1e9, 0, 0, 0, 0]})"), "no error");
  EXPECT_EQ(stress_error(R"({"uniform_kPa": [1e999, 10, 0, 0, 0, 0]})"), "case.json: invalid JSON: number overflow parsing '1e999'");
  EXPECT_EQ(stress_error(R"({"uniform_kPa": [20, 10, 0]})"),
            "case.json: /residual_stress/uniform_kPa is [20,10,0]; expected [xx, yy, zz, xy, xz, yz] (six finite stresses in kPa)");
  EXPECT_EQ(stress_error(R"({"per_label_kPa": {"3": [1, 0, 0, 0, 0, 0]}})"),
            "case.json: /residual_stress/per_label_kPa: label 3 is not in the model; labels present: 1");
  EXPECT_EQ(stress_error(R"({})"), "case.json: /residual_stress: give exactly one of uniform_kPa or per_label_kPa");
}

const DataArray& find_array(const std::vector<DataArray>& arrays, const std::string& name) {
  for (const DataArray& a : arrays)
    if (a.name == name) return a;
  throw std::runtime_error("no array " + name);
}

TEST(MechanicsStage, UniformStressOnAFreePlateIsFullyReleased) {
  // A free body cannot hold a uniform stress: after release the total stress is zero everywhere
  // and the plate contracts by the plane-stress strain -(1 - nu) p / E in x and y and thickens
  // by 2 nu p / E.
  const CaseFile c = case_from(R"(, "residual_stress": {"uniform_kPa": [12, 12, 0, 0, 0, 0]},
                                   "simulation": {"mode": "static", "solver": "cholmod", "tolerance": 1e-12, "fixed": "free"})");
  RunContext ctx{c, std::filesystem::temp_directory_path(), {}, test::make_box_model({6, 4, 1}, 2.0, 80.0, 0.4), {}, {}, {}, {}, nlohmann::json::object(),
                 nlohmann::json::object(), {}};
  stage_mechanics(ctx);
  const LinkedVolume& volume = ctx.model.volume;
  ASSERT_EQ(ctx.displacement_mm.size(), static_cast<std::size_t>(volume.vertex_count()));
  const double strain = -(1 - 0.4) * 12.0 / 80.0;
  const double thickening = 2 * 0.4 * 12.0 / 80.0;
  const Vec3 centre{6.0, 4.0, 1.0};
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const Vec3 x = volume.vertex_position_mm(v) - centre;
    EXPECT_NEAR(ctx.displacement_mm[static_cast<std::size_t>(v)].x(), strain * x.x(), 1e-9);
    EXPECT_NEAR(ctx.displacement_mm[static_cast<std::size_t>(v)].y(), strain * x.y(), 1e-9);
    EXPECT_NEAR(ctx.displacement_mm[static_cast<std::size_t>(v)].z(), thickening * x.z(), 1e-9);
  }
  const DataArray& stress = find_array(ctx.fields.cell_data, "stress");
  const DataArray& residual = find_array(ctx.fields.cell_data, "residual_stress");
  ASSERT_EQ(stress.values.size(), 6u * static_cast<std::size_t>(volume.cell_count()));
  for (double s : stress.values) EXPECT_NEAR(s, 0.0, 1e-6);  // Pa
  EXPECT_EQ(residual.values[0], 12000.0);                    // 12 kPa written in Pa
  EXPECT_EQ(find_array(ctx.fields.point_data, "displacement").components, 3);
  EXPECT_EQ(find_array(ctx.fields.point_data, "fixed").values, std::vector<double>(static_cast<std::size_t>(volume.vertex_count()), 0.0));
  EXPECT_NEAR(ctx.summary["mechanics"]["max_displacement_mm"].get<double>(), Vec3(strain * 6.0, strain * 4.0, thickening).norm(), 1e-9);
}

TEST(MechanicsStage, DynamicRunWritesFramesAndHoldsTheFixedBox) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "cleave_fem_stage_test";
  std::filesystem::create_directories(out);
  const CaseFile c = case_from(R"(, "residual_stress": {"uniform_kPa": [12, 6, 0, 0, 0, 0]},
      "simulation": {"mode": "dynamic", "solver": "cholmod", "time_step_s": 0.001, "steps": 20, "steps_per_frame": 5,
                     "frames_every": 2, "damping": {"mass_per_s": 50}, "fixed": {"box_mm": [[-1, -1, -1], [0.5, 9, 9]]}})");
  RunContext ctx{c, out, {}, test::make_box_model({6, 4, 1}, 2.0), {}, {}, {}, {}, nlohmann::json::object(), nlohmann::json::object(), {}};
  stage_mechanics(ctx);
  ASSERT_EQ(ctx.frames.size(), 3u);  // t = 0, 0.01 s, 0.02 s
  EXPECT_NEAR(ctx.frames.back().time_s, 0.02, 1e-12);
  for (const PvdEntry& f : ctx.frames) EXPECT_TRUE(std::filesystem::exists(out / f.file)) << f.file;
  const DataArray& fixed = find_array(ctx.fields.point_data, "fixed");
  const LinkedVolume& volume = ctx.model.volume;
  int held = 0;
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const bool at_left = volume.vertex_position_mm(v).x() < 0.5;
    EXPECT_EQ(fixed.values[static_cast<std::size_t>(v)], at_left ? 1.0 : 0.0);
    if (at_left) {
      ++held;
      EXPECT_EQ(ctx.displacement_mm[static_cast<std::size_t>(v)].norm(), 0.0);
    }
  }
  EXPECT_EQ(held, 5 * 2);
  EXPECT_GT(ctx.summary["mechanics"]["max_displacement_mm"].get<double>(), 0.0);
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace cleave
