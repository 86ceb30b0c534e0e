#include "cleave/io/case_design.hpp"

#include <limits>

namespace cleave {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

DesignStroke parse_stroke(const nlohmann::json& j, const JsonPath& at) {
  json_allow_keys(j, at, {"points", "interior"});
  DesignStroke stroke;
  const nlohmann::json* points = json_find(j, "points");
  if (!points) json_missing(at / "points", "an array of at least two [x, y, z] points (mm)");
  stroke.points_mm = json_points(*points, at / "points");
  if (stroke.points_mm.size() < 2) json_error(at / "points", *points, "at least two points");
  bool distinct = false;
  for (const Vec3& p : stroke.points_mm) distinct = distinct || p != stroke.points_mm.front();
  if (!distinct) json_error(at / "points", *points, "at least two distinct points");
  if (const nlohmann::json* interior = json_find(j, "interior"))
    stroke.placement = json_bool(*interior, at / "interior") ? StrokePlacement::interior : StrokePlacement::surface;
  return stroke;
}

DesignControlPoint parse_control_point(const nlohmann::json& j, const JsonPath& at) {
  json_allow_keys(j, at, {"position", "langer_kPa", "cross_kPa"});
  DesignControlPoint cp;
  const nlohmann::json* position = json_find(j, "position");
  if (!position) json_missing(at / "position", "[x, y, z] (mm) on the body surface");
  cp.position_mm = json_vec3(*position, at / "position");
  const nlohmann::json* langer = json_find(j, "langer_kPa");
  if (!langer) json_missing(at / "langer_kPa", "the eigenvalue along Langer's line (kPa)");
  cp.langer_kPa = json_stress_kPa(*langer, at / "langer_kPa");
  const nlohmann::json* cross = json_find(j, "cross_kPa");
  if (!cross) json_missing(at / "cross_kPa", "the eigenvalue across Langer's line (kPa)");
  cp.cross_kPa = json_stress_kPa(*cross, at / "cross_kPa");
  return cp;
}

DesignWeights parse_weights(const nlohmann::json& j, const JsonPath& at) {
  json_allow_keys(j, at, {"laplacian", "constraint", "equilibrium"});
  DesignWeights w;
  const double smallest_positive = std::numeric_limits<double>::min();
  if (const auto* v = json_find(j, "laplacian"))
    w.laplacian = json_number_in(*v, at / "laplacian", smallest_positive, kInfinity, "a positive finite weight");
  if (const auto* v = json_find(j, "constraint"))
    w.constraint = json_number_in(*v, at / "constraint", smallest_positive, kInfinity, "a positive finite weight");
  if (const auto* v = json_find(j, "equilibrium"))
    w.equilibrium = json_number_in(*v, at / "equilibrium", 0.0, kInfinity, "a finite weight >= 0 (0 = off)");
  return w;
}

}  // namespace

StressDesign parse_design_settings_json(const nlohmann::json& design, const JsonPath& at) {
  json_allow_keys(design, at, {"strokes", "control_points", "weights", "equilibrate", "equilibrium_support", "solver",
                                  "snap_tolerance_cells"});
  StressDesign d;
  if (const nlohmann::json* weights = json_find(design, "weights")) d.weights = parse_weights(*weights, at / "weights");
  if (const nlohmann::json* equilibrate = json_find(design, "equilibrate"))
    d.equilibration = json_bool(*equilibrate, at / "equilibrate") ? Equilibration::growth : Equilibration::none;
  if (const nlohmann::json* support = json_find(design, "equilibrium_support")) {
    const std::string name = support->is_string() ? support->get<std::string>() : std::string();
    if (name == "none") {
      d.support = EquilibriumSupport::none;
    } else if (name == "simulation") {
      d.support = EquilibriumSupport::simulation;
    } else {
      json_error(at / "equilibrium_support", *support, "\"none\" (free body) or \"simulation\" (the vertices the simulation holds)");
    }
  }
  if (const nlohmann::json* solver = json_find(design, "solver")) {
    const std::string name = solver->is_string() ? solver->get<std::string>() : std::string();
    if (name == "default") {
      d.solver = EigenvalueSolver::cholesky;
    } else if (name == "paper-cg") {
      d.solver = EigenvalueSolver::paper_cg;
    } else {
      json_error(at / "solver", *solver, "\"default\" or \"paper-cg\"");
    }
  }
  if (const nlohmann::json* tolerance = json_find(design, "snap_tolerance_cells"))
    d.snap_tolerance_cells = json_number_in(*tolerance, at / "snap_tolerance_cells", 1e-3, 1e3,
                                            "a snap tolerance from 0.001 to 1000 cell sizes");
  return d;
}

StressDesign parse_design_json(const nlohmann::json& design, const JsonPath& at) {
  StressDesign d = parse_design_settings_json(design, at);
  if (const nlohmann::json* strokes = json_find(design, "strokes")) {
    if (!strokes->is_array()) json_error(at / "strokes", *strokes, "an array of strokes {\"points\": [[x, y, z], ...]}");
    for (std::size_t i = 0; i < strokes->size(); ++i) d.strokes.push_back(parse_stroke((*strokes)[i], at / "strokes" / i));
  }
  const nlohmann::json* control_points = json_find(design, "control_points");
  const std::string cp_expected =
      "at least one control point {\"position\": [x, y, z], \"langer_kPa\": .., \"cross_kPa\": ..}; without one the "
      "stress would silently be zero";
  if (!control_points) json_missing(at / "control_points", cp_expected);
  if (!control_points->is_array() || control_points->empty()) json_error(at / "control_points", *control_points, cp_expected);
  for (std::size_t i = 0; i < control_points->size(); ++i)
    d.control_points.push_back(parse_control_point((*control_points)[i], at / "control_points" / i));
  return d;
}

std::optional<StressDesign> parse_case_design(const CaseFile& case_file) {
  const nlohmann::json* design = case_file.section("design");
  if (!design) return std::nullopt;
  return parse_design_json(*design, case_file.at("design"));
}

}  // namespace cleave
