#pragma once
// One design edit, applied to a design state: the commands a client sends that change the
// design (the journal stores exactly these). Pure: the input state is not modified.
//
//   {"cmd":"add_stroke", "points_mm":[[x,y,z],...]}
//   {"cmd":"move_stroke", "id":3, "offset_mm":[dx,dy,dz]}      (every point moves by the offset)
//   {"cmd":"delete_stroke", "id":3}
//   {"cmd":"add_control_point", "position_mm":[x,y,z], "langer_kPa":20, "cross_kPa":10}
//   {"cmd":"set_control_point", "id":4, "langer_kPa":25}        (any of langer_kPa, cross_kPa, position_mm)
//   {"cmd":"delete_control_point", "id":4}
//   {"cmd":"add_cut", "kind":"scalpel"|"flap", "path_mm":[...], "depth_mm":5}
//   {"cmd":"delete_cut", "id":5}
//   {"cmd":"reset_cuts"}                                          (restores the uncut body)
//   {"cmd":"replace_design", "design":{...design_state JSON...}}  (a loaded case)
//
// Errors: InputError "<where>: /<field> is <value>; expected ..." for a bad field, "... no stroke
// with id 7" for an unknown id, "unknown command 'x'" (is_design_edit() tells beforehand).
#include <nlohmann/json.hpp>
#include <string>

#include "studio/design_state.hpp"

namespace cleave::studio {

/// True when `cmd` names one of the edits above.
bool is_design_edit(const std::string& cmd);

/// The state after `edit`. New items get state.next_id (which then increases).
DesignState apply_design_edit(const DesignState& state, const nlohmann::json& edit, const std::string& where);

}  // namespace cleave::studio
