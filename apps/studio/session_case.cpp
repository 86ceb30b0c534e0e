#include "studio/session_case.hpp"

#include "cleave/io/json_fields.hpp"

namespace cleave::studio {

nlohmann::json case_with_design(nlohmann::json case_document, const DesignState& design) {
  nlohmann::json j = to_json(design);
  for (const char* key : {"strokes", "control_points", "cuts"})
    for (auto& item : j[key]) item.erase("id");
  case_document["design"] = {{"strokes", j["strokes"]}, {"control_points", j["control_points"]}};
  if (design.cuts.empty()) case_document.erase("cuts");
  else case_document["cuts"] = j["cuts"];
  return case_document;
}

DesignState design_from_case(const nlohmann::json& case_document, const std::string& file, int first_id) {
  nlohmann::json j = {{"strokes", nlohmann::json::array()}, {"control_points", nlohmann::json::array()},
                      {"cuts", nlohmann::json::array()}};
  const JsonPath at{file, ""};
  if (const auto* design = json_find(case_document, "design")) {
    if (!design->is_object()) json_error(at / "design", *design, "an object with strokes and control_points");
    json_allow_keys(*design, at / "design", {"strokes", "control_points"});
    for (const char* key : {"strokes", "control_points"})
      if (const auto* items = json_find(*design, key)) j[key] = *items;
  }
  if (const auto* cuts = json_find(case_document, "cuts")) j["cuts"] = *cuts;
  int id = first_id;
  for (const char* key : {"strokes", "control_points", "cuts"}) {
    if (!j[key].is_array()) json_error(at / (std::string(key) == "cuts" ? "cuts" : "design/" + std::string(key)), j[key],
                                       "an array");
    for (auto& item : j[key])
      if (item.is_object()) item["id"] = id++;
  }
  j["next_id"] = id;
  return design_state_from_json(j, file);
}

}  // namespace cleave::studio
