#pragma once
// The studio's design as case-file sections and back, so that a saved session runs with
// `cleave run` and a case loads into the studio (docs/case-format.md):
//   "design": {"strokes":[{"points":[[x,y,z],...]}],             (io/case_design.hpp)
//              "control_points":[{"position":[x,y,z],"langer_kPa":20,"cross_kPa":10}]}
//   "cuts":   [{"type":"scalpel"|"flap","path_mm":[[x,y,z],...],"depth_mm":5}]   (io/case_cuts.hpp; flaps "shape":"u")
// Ids are session-local and not saved; loading numbers the items from `first_id`.
#include <nlohmann/json.hpp>
#include <string>

#include "studio/design_state.hpp"

namespace cleave::studio {

/// `case_document` with its "design" and "cuts" sections replaced by `design`'s.
nlohmann::json case_with_design(nlohmann::json case_document, const DesignState& design);

/// The design held by a case document (empty sections when absent). InputError naming `file`
/// and the JSON path for a malformed section.
DesignState design_from_case(const nlohmann::json& case_document, const std::string& file, int first_id);

}  // namespace cleave::studio
