#include "cleave/io/case_mechanics.hpp"

#include <fmt/format.h>
#include <limits>
#include <set>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSmallest = std::numeric_limits<double>::min();
constexpr int kMaxSteps = 100000000;
constexpr int kMaxIterations = 100000000;

SimulationMode parse_mode(const nlohmann::json& value, const JsonPath& at) {
  constexpr const char* kExpected = "\"static\" or \"dynamic\"";
  if (!value.is_string()) json_error(at, value, kExpected);
  const std::string s = value.get<std::string>();
  if (s == "static") return SimulationMode::static_equilibrium;
  if (s == "dynamic") return SimulationMode::dynamic;
  json_error(at, value, kExpected);
}

SolverKind parse_solver(const nlohmann::json& value, const JsonPath& at) {
  constexpr const char* kExpected = "\"multigrid\", \"eigen-cg\" or \"cholmod\"";
  if (!value.is_string()) json_error(at, value, kExpected);
  const std::string s = value.get<std::string>();
  if (s == "multigrid") return SolverKind::multigrid_cg;
  if (s == "eigen-cg") return SolverKind::eigen_cg;
  if (s == "cholmod") return SolverKind::cholmod;
  json_error(at, value, kExpected);
}

void parse_fixed_entry(const nlohmann::json& value, const JsonPath& at, SimulationSettings& s) {
  if (const nlohmann::json* surface = value.is_object() ? json_find(value, "surface") : nullptr) {
    json_allow_keys(value, at, {"surface"});
    if (!surface->is_string() || surface->get<std::string>() != "inner") json_error(at / "surface", *surface, "\"inner\"");
    s.fixed_surfaces.push_back(FixedSurface::inner);
    return;
  }
  json_allow_keys(value, at, {"box_mm"});
  const nlohmann::json* box = json_find(value, "box_mm");
  if (!box) json_missing(at / "box_mm", "[[x0, y0, z0], [x1, y1, z1]] (mm)");
  if (!box->is_array() || box->size() != 2) json_error(at / "box_mm", *box, "[[x0, y0, z0], [x1, y1, z1]] (mm)");
  FixedBox out{json_vec3((*box)[0], at / "box_mm" / 0), json_vec3((*box)[1], at / "box_mm" / 1)};
  if ((out.lo_mm.array() > out.hi_mm.array()).any())
    json_error(at / "box_mm", *box, "a lower corner [x0, y0, z0] not above the upper corner [x1, y1, z1]");
  s.fixed_boxes.push_back(out);
}

void parse_fixed(const nlohmann::json& value, const JsonPath& at, SimulationSettings& s) {
  constexpr const char* kExpected =
      "\"none\", \"free\", {\"box_mm\": [[x0, y0, z0], [x1, y1, z1]]}, {\"surface\": \"inner\"} or an array of such";
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    if (name == "none" || name == "free") return;
    json_error(at, value, kExpected);
  }
  if (value.is_object()) return parse_fixed_entry(value, at, s);
  if (!value.is_array()) json_error(at, value, kExpected);
  for (std::size_t i = 0; i < value.size(); ++i) parse_fixed_entry(value[i], at / i, s);
}

Vec6 parse_voigt_kPa(const nlohmann::json& value, const JsonPath& at) {
  constexpr const char* kExpected = "[xx, yy, zz, xy, xz, yz] (six finite stresses in kPa)";
  if (!value.is_array() || value.size() != 6) json_error(at, value, kExpected);
  Vec6 s;
  for (std::size_t i = 0; i < 6; ++i)
    s[static_cast<Eigen::Index>(i)] = json_stress_kPa(value[i], at / i);
  return s;
}

}  // namespace

SimulationSettings parse_simulation_settings(const CaseFile& case_file) {
  SimulationSettings s;
  const nlohmann::json* section = case_file.section("simulation");
  if (!section) return s;
  const JsonPath at = case_file.at("simulation");
  json_allow_keys(*section, at,
                  {"mode", "solver", "tolerance", "max_iterations", "iterations_per_step", "time_step_s", "steps",
                   "steps_per_frame", "frames_every", "damping", "fixed", "gravity_mm_per_s2"});
  if (const auto* v = json_find(*section, "mode")) s.mode = parse_mode(*v, at / "mode");
  if (const auto* v = json_find(*section, "solver")) s.solver = parse_solver(*v, at / "solver");
  if (const auto* v = json_find(*section, "tolerance"))
    s.solve.relative_tolerance = json_number_in(*v, at / "tolerance", kSmallest, std::nextafter(1.0, 0.0),
                                                "a relative residual tolerance in (0, 1)");
  if (const auto* v = json_find(*section, "max_iterations"))
    s.solve.max_iterations = json_int_in(*v, at / "max_iterations", 1, kMaxIterations);
  if (const auto* v = json_find(*section, "iterations_per_step"))
    s.iterations_per_step = json_int_in(*v, at / "iterations_per_step", 0, kMaxIterations);
  if (const auto* v = json_find(*section, "time_step_s"))
    s.time_step_s = json_number_in(*v, at / "time_step_s", kSmallest, kInf, "a positive time step in s");
  if (const auto* v = json_find(*section, "steps")) s.steps = json_int_in(*v, at / "steps", 1, kMaxSteps);
  if (const auto* v = json_find(*section, "steps_per_frame"))
    s.steps_per_frame = json_int_in(*v, at / "steps_per_frame", 1, kMaxSteps);
  if (const auto* v = json_find(*section, "frames_every")) s.frames_every = json_int_in(*v, at / "frames_every", 0, kMaxSteps);
  if (const auto* d = json_find(*section, "damping")) {
    const JsonPath here = at / "damping";
    json_allow_keys(*d, here, {"mass_per_s", "stiffness_s", "numerical", "high_frequency_radius"});
    if (const auto* v = json_find(*d, "mass_per_s"))
      s.mass_damping_per_s = json_number_in(*v, here / "mass_per_s", 0.0, kInf, "a non-negative mass damping in 1/s");
    if (const auto* v = json_find(*d, "stiffness_s"))
      s.stiffness_damping_s = json_number_in(*v, here / "stiffness_s", 0.0, kInf, "a non-negative stiffness damping in s");
    if (const auto* v = json_find(*d, "numerical"))
      s.numerical_damping = json_number_in(*v, here / "numerical", 0.0, 1.0 / 3.0, "a numerical damping (HHT -alpha) from 0 to 1/3");
    if (const auto* v = json_find(*d, "high_frequency_radius"))
      s.high_frequency_radius = json_number_in(*v, here / "high_frequency_radius", 0.0, 1.0,
                                               "a spectral radius from 0 to 1 (generalized-alpha)");
  }
  if (const auto* v = json_find(*section, "fixed")) parse_fixed(*v, at / "fixed", s);
  if (const auto* v = json_find(*section, "gravity_mm_per_s2")) s.gravity_mm_per_s2 = json_vec3(*v, at / "gravity_mm_per_s2");
  return s;
}

std::optional<std::vector<Vec6>> parse_direct_residual_stress(const CaseFile& case_file, const TissueModel& model) {
  const nlohmann::json* section = case_file.section("residual_stress");
  if (!section) return std::nullopt;
  const JsonPath at = case_file.at("residual_stress");
  json_allow_keys(*section, at, {"uniform_kPa", "per_label_kPa"});
  const nlohmann::json* uniform = json_find(*section, "uniform_kPa");
  const nlohmann::json* per_label = json_find(*section, "per_label_kPa");
  if ((uniform == nullptr) == (per_label == nullptr))
    throw InputError(fmt::format("{}: give exactly one of uniform_kPa or per_label_kPa", at.str()));
  const LinkedVolume& volume = model.volume;
  const auto cells = static_cast<std::size_t>(volume.cell_count());
  if (uniform) return std::vector<Vec6>(cells, parse_voigt_kPa(*uniform, at / "uniform_kPa"));

  const JsonPath here = at / "per_label_kPa";
  if (!per_label->is_object()) json_error(here, *per_label, "an object mapping label numbers to [xx, yy, zz, xy, xz, yz] in kPa");
  std::set<int> present;
  for (CellId c = 0; c < volume.cell_count(); ++c) present.insert(volume.cell_label(c));
  std::array<Vec6, 256> by_label;
  by_label.fill(Vec6::Zero());
  for (const auto& [key, value] : per_label->items()) {
    int label = -1;
    try {
      std::size_t used = 0;
      label = std::stoi(key, &used);
      if (used != key.size()) label = -1;
    } catch (const std::exception&) {
      label = -1;
    }
    if (label < 1 || label > 255)
      throw InputError(fmt::format("{}: key '{}' is not a label; expected a label number from 1 to 255", here.str(), key));
    if (!present.contains(label))
      throw InputError(fmt::format("{}: label {} is not in the model; labels present: {}", here.str(), label,
                                   fmt::join(present, ", ")));
    by_label[static_cast<std::size_t>(label)] = parse_voigt_kPa(value, here / key);
  }
  std::vector<Vec6> out(cells);
  for (CellId c = 0; c < volume.cell_count(); ++c) out[static_cast<std::size_t>(c)] = by_label[volume.cell_label(c)];
  return out;
}

}  // namespace cleave
