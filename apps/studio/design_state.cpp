#include "studio/design_state.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/json_fields.hpp"
#include "studio/design_limits.hpp"

namespace cleave::studio {
namespace {

nlohmann::json points_to_json(const std::vector<Vec3>& points) {
  nlohmann::json a = nlohmann::json::array();
  for (const Vec3& p : points) a.push_back({p.x(), p.y(), p.z()});
  return a;
}

}  // namespace

std::vector<Vec3> path_from_json(const nlohmann::json& j, const JsonPath& at) {
  if (!j.is_array() || j.size() < 2 || j.size() > kMaxPathPoints)
    json_error(at, j.is_array() ? nlohmann::json(j.size()) : j,
               fmt::format("an array of 2 to {} points [x, y, z] in mm", kMaxPathPoints));
  std::vector<Vec3> points;
  points.reserve(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) {
    Vec3 p = json_vec3(j[i], at / i);
    if (p.cwiseAbs().maxCoeff() > kMaxCoordinate_mm)
      json_error(at / i, j[i], fmt::format("coordinates within +-{} mm", kMaxCoordinate_mm));
    points.push_back(p);
  }
  return points;
}

namespace {

int id_from_json(const nlohmann::json& object, const JsonPath& at) {
  const nlohmann::json* id = json_find(object, "id");
  if (!id) json_missing(at / "id", "a positive integer id");
  return json_int_in(*id, at / "id", 1, std::numeric_limits<int>::max());
}

}  // namespace

bool DesignState::operator==(const DesignState& other) const { return to_json(*this) == to_json(other); }

std::string to_string(CutKind kind) { return kind == CutKind::flap ? "flap" : "scalpel"; }

CutKind cut_kind_from_json(const nlohmann::json& object, const JsonPath& at) {
  const nlohmann::json* kind = json_find(object, "kind");
  if (!kind) return CutKind::scalpel;
  const std::string k = json_string(*kind, at / "kind");
  if (k == "scalpel") return CutKind::scalpel;
  if (k == "flap") return CutKind::flap;
  json_error(at / "kind", *kind, "\"scalpel\" or \"flap\"");
}

Vec3 position_from_json(const nlohmann::json& j, const JsonPath& at) {
  Vec3 p = json_vec3(j, at);
  if (p.cwiseAbs().maxCoeff() > kMaxCoordinate_mm)
    json_error(at, j, fmt::format("coordinates within +-{} mm", kMaxCoordinate_mm));
  return p;
}

nlohmann::json to_json(const DesignState& state) {
  nlohmann::json strokes = nlohmann::json::array();
  for (const Stroke& s : state.strokes) strokes.push_back({{"id", s.id}, {"points_mm", points_to_json(s.points_mm)}});
  nlohmann::json points = nlohmann::json::array();
  for (const ControlPoint& p : state.control_points)
    points.push_back({{"id", p.id},
                      {"position_mm", {p.position_mm.x(), p.position_mm.y(), p.position_mm.z()}},
                      {"langer_kPa", p.langer_kPa},
                      {"cross_kPa", p.cross_kPa}});
  nlohmann::json cuts = nlohmann::json::array();
  for (const Cut& c : state.cuts)
    cuts.push_back({{"id", c.id}, {"kind", to_string(c.kind)}, {"path_mm", points_to_json(c.path_mm)}, {"depth_mm", c.depth_mm}});
  return {{"strokes", strokes}, {"control_points", points}, {"cuts", cuts}, {"next_id", state.next_id}};
}

DesignState design_state_from_json(const nlohmann::json& j, const std::string& where) {
  const JsonPath at{where, ""};
  if (!j.is_object()) json_error(at, j, "a design object with strokes, control_points, cuts, next_id");
  json_allow_keys(j, at, {"strokes", "control_points", "cuts", "next_id"});
  DesignState state;
  int max_id = 0;
  const auto array_at = [&](const char* key) -> const nlohmann::json& {
    static const nlohmann::json kEmpty = nlohmann::json::array();
    const nlohmann::json* a = json_find(j, key);
    if (!a) return kEmpty;
    if (!a->is_array() || a->size() > kMaxDesignItems)
      json_error(at / key, *a, fmt::format("an array of at most {} items", kMaxDesignItems));
    return *a;
  };
  const nlohmann::json& strokes = array_at("strokes");
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    const JsonPath here = at / "strokes" / i;
    json_allow_keys(strokes[i], here, {"id", "points_mm"});
    Stroke s{id_from_json(strokes[i], here), {}};
    const nlohmann::json* pts = json_find(strokes[i], "points_mm");
    if (!pts) json_missing(here / "points_mm", "the stroke's points");
    s.points_mm = path_from_json(*pts, here / "points_mm");
    max_id = std::max(max_id, s.id);
    state.strokes.push_back(std::move(s));
  }
  const nlohmann::json& points = array_at("control_points");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const JsonPath here = at / "control_points" / i;
    json_allow_keys(points[i], here, {"id", "position_mm", "langer_kPa", "cross_kPa"});
    ControlPoint p;
    p.id = id_from_json(points[i], here);
    const nlohmann::json* pos = json_find(points[i], "position_mm");
    if (!pos) json_missing(here / "position_mm", "the point's position [x, y, z] in mm");
    p.position_mm = position_from_json(*pos, here / "position_mm");
    if (const auto* v = json_find(points[i], "langer_kPa"))
      p.langer_kPa = json_number_in(*v, here / "langer_kPa", -kMaxEigenvalue_kPa, kMaxEigenvalue_kPa, "an eigenvalue in kPa");
    if (const auto* v = json_find(points[i], "cross_kPa"))
      p.cross_kPa = json_number_in(*v, here / "cross_kPa", -kMaxEigenvalue_kPa, kMaxEigenvalue_kPa, "an eigenvalue in kPa");
    max_id = std::max(max_id, p.id);
    state.control_points.push_back(p);
  }
  const nlohmann::json& cuts = array_at("cuts");
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    const JsonPath here = at / "cuts" / i;
    json_allow_keys(cuts[i], here, {"id", "kind", "path_mm", "depth_mm"});
    Cut c;
    c.id = id_from_json(cuts[i], here);
    c.kind = cut_kind_from_json(cuts[i], here);
    const nlohmann::json* path = json_find(cuts[i], "path_mm");
    if (!path) json_missing(here / "path_mm", "the cut's path");
    c.path_mm = path_from_json(*path, here / "path_mm");
    if (const auto* d = json_find(cuts[i], "depth_mm"))
      c.depth_mm = json_number_in(*d, here / "depth_mm", 0, kMaxCutDepth_mm, "a depth in mm");
    if (!(c.depth_mm > 0)) json_error(here / "depth_mm", c.depth_mm, "a positive depth in mm");
    max_id = std::max(max_id, c.id);
    state.cuts.push_back(std::move(c));
  }
  if (state.strokes.size() + state.control_points.size() + state.cuts.size() > kMaxDesignItems)
    json_error(at, "too many items", fmt::format("at most {} strokes, control points and cuts", kMaxDesignItems));
  state.next_id = max_id + 1;
  if (const auto* n = json_find(j, "next_id"))
    state.next_id = std::max(state.next_id, json_int_in(*n, at / "next_id", 1, std::numeric_limits<int>::max() - 1));
  return state;
}

}  // namespace cleave::studio
