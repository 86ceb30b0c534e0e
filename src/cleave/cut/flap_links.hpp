#pragma once
// The links a flap cuts: the wall along its path down to the flap's depth plus the undercut, a
// surface parallel to the skin at that depth under the region the path encloses. The path is
// projected onto the tangent plane at its centroid (normal: the mean surface normal along the
// path), where it must form a simple polygon (a U-shaped path is closed by the chord between its
// ends, the hinge). Flap cells are the cells whose centres project inside that polygon and lie
// less than the depth below the skin (measured along the normal to where the body ends). Every
// link from a flap cell to a non-flap cell is cut, except, for a U-shaped flap, links whose
// projection crosses the hinge.
//
//   FlapRegion region = flap_region(surface, flap, tolerance_mm);   // throws InputError
//   std::vector<CellFace> links = flap_links(model.volume, region);
#include <Eigen/Core>
#include <vector>

#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/cut_requests.hpp"

namespace cleave {

using Vec2 = Eigen::Vector2d;

struct FlapRegion {
  Vec3 origin_mm = Vec3::Zero();  ///< centroid of the snapped path
  Vec3 normal = Vec3::UnitZ();    ///< outward, mean over the path
  Vec3 tangent_u = Vec3::UnitX();
  Vec3 tangent_v = Vec3::UnitY();
  std::vector<Vec2> polygon;      ///< the path in (u, v) coordinates (mm); for a U the hinge joins last to first
  FlapShape shape = FlapShape::u_shaped;
  double depth_mm = 0;
  std::vector<CellId> cells;      ///< the flap's cells

  Vec2 to_plane(const Vec3& p_mm) const {
    const Vec3 d = p_mm - origin_mm;
    return {d.dot(tangent_u), d.dot(tangent_v)};
  }
};

/// Index pairs (i, j) of non-adjacent edges of the closed polygon that intersect; empty when the
/// polygon is simple. Edge i runs from point i to point (i + 1) mod n.
std::vector<std::pair<std::size_t, std::size_t>> polygon_self_intersections(const std::vector<Vec2>& polygon);

/// True when p lies inside the closed polygon (crossing number).
bool polygon_contains(const std::vector<Vec2>& polygon, const Vec2& p);

/// Snaps the path, builds the plane and polygon and finds the flap cells. Throws InputError for a
/// path point off the surface (beyond `tolerance_mm`), fewer than 3 distinct points, an enclosed
/// area of less than one cell face, or a self-intersecting path.
FlapRegion flap_region(const BodySurface& surface, const Flap& flap, double tolerance_mm);

std::vector<CellFace> flap_links(const LinkedVolume& volume, const FlapRegion& region);

}  // namespace cleave
