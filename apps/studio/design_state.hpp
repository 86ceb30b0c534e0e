#pragma once
// What the user designs in the studio, as plain data: Langer-direction strokes, eigenvalue
// control points and cuts. Positions are on the body surface in mm (model coordinates);
// eigenvalues in kPa; depths in mm. Every item has a session-unique id (never reused) so that
// clients can select, move and delete it.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cleave/core/types.hpp"
#include "cleave/io/json_fields.hpp"

namespace cleave::studio {

/// A stroke drawn on the surface (paper fig. 3): a polyline giving the Langer direction.
struct Stroke {
  int id = 0;
  std::vector<Vec3> points_mm;  ///< at least 2 points, in drawing order
};

/// A magnitude control point (paper fig. 4): the eigenvalues along Langer's line and across it
/// (the normal eigenvalue is 0 on the free surface).
struct ControlPoint {
  int id = 0;
  Vec3 position_mm = Vec3::Zero();
  double langer_kPa = 20;  ///< paper section 7: typical tension along Langer's lines
  double cross_kPa = 10;   ///< and across them
};

enum class CutKind { scalpel, flap };

/// A cut drawn on the surface: an open scalpel path or a closed flap outline, to a depth.
struct Cut {
  int id = 0;
  CutKind kind = CutKind::scalpel;
  std::vector<Vec3> path_mm;  ///< at least 2 points
  double depth_mm = 5;
};

struct DesignState {
  std::vector<Stroke> strokes;
  std::vector<ControlPoint> control_points;
  std::vector<Cut> cuts;
  int next_id = 1;  ///< the id the next added item gets

  bool operator==(const DesignState& other) const;
};

std::string to_string(CutKind kind);

/// JSON form used in messages, the journal and snapshots:
///   {"strokes":[{"id":1,"points_mm":[[x,y,z],...]}], "control_points":[{"id":2,"position_mm":[..],
///    "langer_kPa":20,"cross_kPa":10}], "cuts":[{"id":3,"kind":"scalpel","path_mm":[..],"depth_mm":5}],
///    "next_id":4}
nlohmann::json to_json(const DesignState& state);
/// Inverse of to_json; validates every field (InputError naming `where` and the JSON path).
DesignState design_state_from_json(const nlohmann::json& j, const std::string& where);

/// A position [x, y, z] in mm within the coordinate bound (design_limits.hpp), else InputError.
Vec3 position_from_json(const nlohmann::json& j, const JsonPath& at);
/// A path of 2..kMaxPathPoints positions, else InputError.
std::vector<Vec3> path_from_json(const nlohmann::json& j, const JsonPath& at);
/// The "kind" key of `object`: "scalpel" (default when absent) or "flap", else InputError.
CutKind cut_kind_from_json(const nlohmann::json& object, const JsonPath& at);

}  // namespace cleave::studio
