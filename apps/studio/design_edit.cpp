#include "studio/design_edit.hpp"

#include <algorithm>
#include <array>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "studio/design_limits.hpp"

namespace cleave::studio {
namespace {

constexpr std::array<const char*, 10> kEdits = {"add_stroke",   "move_stroke", "delete_stroke",  "add_control_point",
                                                "set_control_point", "delete_control_point", "add_cut",
                                                "delete_cut",   "reset_cuts",  "replace_design"};

const nlohmann::json& required(const nlohmann::json& edit, const char* key, const JsonPath& at, const char* expected) {
  const nlohmann::json* v = json_find(edit, key);
  if (!v) json_missing(at / key, expected);
  return *v;
}

int item_id(const nlohmann::json& edit, const JsonPath& at) {
  return json_int_in(required(edit, "id", at, "the id of an existing item"), at / "id", 1,
                     std::numeric_limits<int>::max());
}

template <class Item>
auto find_item(std::vector<Item>& items, int id, const char* what, const JsonPath& at) {
  auto it = std::find_if(items.begin(), items.end(), [id](const Item& i) { return i.id == id; });
  if (it == items.end()) throw InputError(fmt::format("{}: no {} with id {}", at.file, what, id));
  return it;
}

void require_room(const DesignState& s, const JsonPath& at) {
  if (s.strokes.size() + s.control_points.size() + s.cuts.size() >= kMaxDesignItems)
    throw InputError(fmt::format("{}: the design already holds {} items, the most a session keeps", at.str(), kMaxDesignItems));
  if (s.next_id == std::numeric_limits<int>::max()) throw InputError(fmt::format("{}: no item ids left", at.str()));
}

double eigenvalue(const nlohmann::json& v, const JsonPath& at) {
  return json_number_in(v, at, -kMaxEigenvalue_kPa, kMaxEigenvalue_kPa, "an eigenvalue in kPa");
}

}  // namespace

bool is_design_edit(const std::string& cmd) {
  return std::any_of(kEdits.begin(), kEdits.end(), [&](const char* e) { return cmd == e; });
}

DesignState apply_design_edit(const DesignState& state, const nlohmann::json& edit, const std::string& where) {
  const JsonPath at{where, ""};
  if (!edit.is_object()) json_error(at, edit, "an object with a \"cmd\"");
  const std::string cmd = json_string(required(edit, "cmd", at, "a command name"), at / "cmd");
  DesignState s = state;
  if (cmd == "add_stroke") {
    require_room(s, at);
    s.strokes.push_back({s.next_id++, path_from_json(required(edit, "points_mm", at, "the stroke's points"), at / "points_mm")});
  } else if (cmd == "move_stroke") {
    const Vec3 offset = position_from_json(required(edit, "offset_mm", at, "an offset [dx, dy, dz] in mm"), at / "offset_mm");
    auto it = find_item(s.strokes, item_id(edit, at), "stroke", at);
    for (Vec3& p : it->points_mm) {
      p += offset;
      if (p.cwiseAbs().maxCoeff() > kMaxCoordinate_mm)
        json_error(at / "offset_mm", edit["offset_mm"], fmt::format("an offset keeping the stroke within +-{} mm", kMaxCoordinate_mm));
    }
  } else if (cmd == "delete_stroke") {
    s.strokes.erase(find_item(s.strokes, item_id(edit, at), "stroke", at));
  } else if (cmd == "add_control_point" || cmd == "set_control_point") {
    ControlPoint* p = nullptr;
    if (cmd == "add_control_point") {
      require_room(s, at);
      ControlPoint added;
      added.id = s.next_id++;
      added.position_mm = position_from_json(required(edit, "position_mm", at, "the point's position [x, y, z] in mm"),
                                             at / "position_mm");
      s.control_points.push_back(added);
      p = &s.control_points.back();
    } else {
      p = &*find_item(s.control_points, item_id(edit, at), "control point", at);
      if (const auto* pos = json_find(edit, "position_mm")) p->position_mm = position_from_json(*pos, at / "position_mm");
    }
    if (const auto* v = json_find(edit, "langer_kPa")) p->langer_kPa = eigenvalue(*v, at / "langer_kPa");
    if (const auto* v = json_find(edit, "cross_kPa")) p->cross_kPa = eigenvalue(*v, at / "cross_kPa");
  } else if (cmd == "delete_control_point") {
    s.control_points.erase(find_item(s.control_points, item_id(edit, at), "control point", at));
  } else if (cmd == "add_cut") {
    require_room(s, at);
    Cut c;
    c.id = s.next_id++;
    c.kind = cut_kind_from_json(edit, at);
    c.path_mm = path_from_json(required(edit, "path_mm", at, "the cut's path"), at / "path_mm");
    c.depth_mm = json_number_in(required(edit, "depth_mm", at, "a depth in mm"), at / "depth_mm", 0, kMaxCutDepth_mm,
                                "a depth in mm");
    if (!(c.depth_mm > 0)) json_error(at / "depth_mm", edit["depth_mm"], "a positive depth in mm");
    s.cuts.push_back(std::move(c));
  } else if (cmd == "delete_cut") {
    s.cuts.erase(find_item(s.cuts, item_id(edit, at), "cut", at));
  } else if (cmd == "reset_cuts") {
    s.cuts.clear();
  } else if (cmd == "replace_design") {
    DesignState replaced = design_state_from_json(required(edit, "design", at, "a design object"), where + " design");
    replaced.next_id = std::max(replaced.next_id, s.next_id);  // ids are never reused within a session
    s = std::move(replaced);
  } else {
    throw InputError(fmt::format("{}: unknown command '{}'", where, cmd));
  }
  return s;
}

}  // namespace cleave::studio
