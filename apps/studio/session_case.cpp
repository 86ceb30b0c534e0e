#include "studio/session_case.hpp"

#include "cleave/io/json_fields.hpp"

namespace cleave::studio {
namespace {

nlohmann::json path_json(const std::vector<Vec3>& points) {
  nlohmann::json a = nlohmann::json::array();
  for (const Vec3& p : points) a.push_back({p.x(), p.y(), p.z()});
  return a;
}

const nlohmann::json& array_or_empty(const nlohmann::json* value, const JsonPath& at) {
  static const nlohmann::json kEmpty = nlohmann::json::array();
  if (!value) return kEmpty;
  if (!value->is_array()) json_error(at, *value, "an array");
  return *value;
}

}  // namespace

nlohmann::json case_with_design(nlohmann::json case_document, const DesignState& design) {
  nlohmann::json strokes = nlohmann::json::array();
  for (const Stroke& s : design.strokes) strokes.push_back({{"points", path_json(s.points_mm)}});
  nlohmann::json points = nlohmann::json::array();
  for (const ControlPoint& p : design.control_points)
    points.push_back({{"position", {p.position_mm.x(), p.position_mm.y(), p.position_mm.z()}},
                      {"langer_kPa", p.langer_kPa},
                      {"cross_kPa", p.cross_kPa}});
  nlohmann::json design_section = case_document.value("design", nlohmann::json::object());
  design_section["strokes"] = strokes;
  design_section["control_points"] = points;
  case_document["design"] = design_section;
  nlohmann::json cuts = nlohmann::json::array();
  for (const Cut& c : design.cuts) {
    nlohmann::json cut = {{"type", to_string(c.kind)}, {"path_mm", path_json(c.path_mm)}, {"depth_mm", c.depth_mm}};
    if (c.kind == CutKind::flap) cut["shape"] = "u";
    cuts.push_back(cut);
  }
  if (cuts.empty()) case_document.erase("cuts");
  else case_document["cuts"] = cuts;
  return case_document;
}

DesignState design_from_case(const nlohmann::json& case_document, const std::string& file, int first_id) {
  const JsonPath at{file, ""};
  nlohmann::json j = {{"strokes", nlohmann::json::array()}, {"control_points", nlohmann::json::array()},
                      {"cuts", nlohmann::json::array()}};
  int id = first_id;
  if (const auto* design = json_find(case_document, "design")) {
    if (!design->is_object()) json_error(at / "design", *design, "an object with strokes and control_points");
    const auto& strokes = array_or_empty(json_find(*design, "strokes"), at / "design" / "strokes");
    for (std::size_t i = 0; i < strokes.size(); ++i) {
      const JsonPath here = at / "design" / "strokes" / i;
      if (!strokes[i].is_object() || !strokes[i].contains("points")) json_missing(here / "points", "the stroke's points");
      j["strokes"].push_back({{"id", id++}, {"points_mm", strokes[i]["points"]}});
    }
    const auto& points = array_or_empty(json_find(*design, "control_points"), at / "design" / "control_points");
    for (std::size_t i = 0; i < points.size(); ++i) {
      const JsonPath here = at / "design" / "control_points" / i;
      if (!points[i].is_object() || !points[i].contains("position")) json_missing(here / "position", "the point's position");
      nlohmann::json p = {{"id", id++}, {"position_mm", points[i]["position"]}};
      for (const char* key : {"langer_kPa", "cross_kPa"})
        if (points[i].contains(key)) p[key] = points[i][key];
      j["control_points"].push_back(p);
    }
  }
  const auto& cuts = array_or_empty(json_find(case_document, "cuts"), at / "cuts");
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    const JsonPath here = at / "cuts" / i;
    if (!cuts[i].is_object()) json_error(here, cuts[i], "a cut object");
    nlohmann::json c = {{"id", id++}, {"kind", cuts[i].value("type", "scalpel")}};
    for (const char* key : {"path_mm", "depth_mm"})
      if (cuts[i].contains(key)) c[key] = cuts[i][key];
    j["cuts"].push_back(c);
  }
  j["next_id"] = id;
  return design_state_from_json(j, file);
}

}  // namespace cleave::studio
