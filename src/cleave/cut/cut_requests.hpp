#pragma once
// What a user asks to cut, in plain data (positions in mm, reference configuration).
//
//   RoundIncision  a cylinder wall of radius r around the outward surface normal at a surface
//                  point, from just above the skin down to depth d (Langer's round incisions).
//   ScalpelCut     a path on the surface swept inward to depth d: a ruled surface. The sweep
//                  direction is the inward normal, tilted by the blade angle about the path's
//                  tangent.
//   Flap           a closed or U-shaped path cut to depth d plus an undercut parallel to the skin
//                  at that depth under the region the path encloses (for a U, the region closed
//                  by the chord between its ends; the chord is the hinge and stays attached).
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave {

/// What happens to the plug of tissue inside a round incision.
enum class PlugHandling {
  keep,    ///< only the wall is cut; the plug stays attached at its bottom
  remove,  ///< the bottom is cut too; the plug becomes a free piece, hidden from display
};

struct RoundIncision {
  Vec3 centre_mm = Vec3::Zero();  ///< on the surface
  double radius_mm = 0;
  double depth_mm = 0;
  PlugHandling plug = PlugHandling::remove;
};

struct ScalpelCut {
  std::vector<Vec3> path_mm;      ///< polyline near the surface (snapped onto it), >= 2 points
  double depth_mm = 0;
  double blade_angle_deg = 0;     ///< tilt from the inward normal about the path tangent, (-90, 90)
};

enum class FlapShape {
  closed,    ///< the path is a loop (the last point joins the first)
  u_shaped,  ///< the path is open; the chord between its ends is the hinge
};

struct Flap {
  std::vector<Vec3> path_mm;  ///< polyline near the surface, >= 3 points
  double depth_mm = 0;
  FlapShape shape = FlapShape::u_shaped;
};

/// Everything one run cuts, applied in this order: incisions, scalpel cuts, flaps.
struct CutRequests {
  std::vector<RoundIncision> incisions;
  std::vector<ScalpelCut> scalpel_cuts;
  std::vector<Flap> flaps;

  bool empty() const { return incisions.empty() && scalpel_cuts.empty() && flaps.empty(); }
};

}  // namespace cleave
