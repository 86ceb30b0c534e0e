#pragma once
// The case section "design" (issue 4, item 6): the residual stress designed from strokes and
// control points (paper section 4) instead of given directly ("residual_stress").
//
//   "design": {
//     "strokes": [ {"points": [[x, y, z], ...], "interior": false}, ... ],   mm; >= 2 points each
//     "control_points": [ {"position": [x, y, z], "langer_kPa": 20, "cross_kPa": 10}, ... ],  >= 1
//     "weights": {"laplacian": 1, "constraint": 1000, "equilibrium": 0},       optional, defaults shown
//     "equilibrate": true,                                                     optional, default true
//     "equilibrium_support": "simulation" | "none",                            optional, default "simulation"
//     "solver": "default" | "paper-cg",                                        optional, default "default"
//     "snap_tolerance_cells": 2                                                optional, > 0
//   }
//
// "equilibrium_support": "simulation" imposes equilibrium (eq. 6 rows and the exact equilibration)
// only at the vertices that "simulation"/"fixed" leaves free: the held ones carry reactions, as
// tissue stretched over a frame (paper eq. 2 holds on the free surface only); a case that holds
// nothing is a free body either way. "none": balance as a free body even where the case holds it.
// Defaults (w_E = 0, equilibrate, support from the simulation): the control points are reproduced
// and the exact equilibration balances the field (docs/stress-design.md says why).
// "interior": true marks a stroke inside the body (not snapped). Errors are InputErrors naming the
// file, JSON path, value and expectation, e.g.
//   "case.json: /design/strokes/2/points is [[0,0,0]]; expected at least two points".
// Whether points lie on/in the body is checked when the design is computed (it needs the model).
#include <optional>

#include "cleave/io/case_file.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave {

/// The parsed section, or nullopt when the case has no "design".
std::optional<StressDesign> parse_case_design(const CaseFile& case_file);

/// The same from the section's JSON value (`at` names where it came from, for messages).
StressDesign parse_design_json(const nlohmann::json& design, const JsonPath& at);

/// Only the settings of the section (weights, equilibrate, equilibrium_support, solver,
/// snap_tolerance_cells), with no strokes or control points: for the studio, whose strokes and
/// points come from its own edits. Keys are checked as in parse_design_json.
StressDesign parse_design_settings_json(const nlohmann::json& design, const JsonPath& at);

}  // namespace cleave
