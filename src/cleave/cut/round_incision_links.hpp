#pragma once
// The links a round incision cuts (paper section 5): the wall of a cylinder of radius r whose
// axis is the outward surface normal at the incision's centre, from one cell above the skin down
// to depth d below the centre's tangent plane. A link is cut when its dual segment meets that
// wall. With PlugHandling::remove every remaining link of the plug (cells whose centres lie
// inside the cylinder, above depth d) is cut too, so the plug becomes a free piece.
//
//   IncisionFrame frame = incision_frame(surface, incision);      // snaps the centre to the skin
//   IncisionLinks cut = round_incision_links(model.volume, frame, incision.plug);
//   model.volume.cut_links(cut.links);
#include <vector>

#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/cut_requests.hpp"

namespace cleave {

/// Where an incision sits: centre on the surface, outward unit normal, and two unit tangents
/// (u, v, normal right-handed). u is the world axis least aligned with the normal, projected
/// into the tangent plane.
struct IncisionFrame {
  Vec3 centre_mm = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  Vec3 tangent_u = Vec3::UnitX();
  Vec3 tangent_v = Vec3::UnitY();
  double radius_mm = 0;
  double depth_mm = 0;

  /// Depth of p below the tangent plane (mm, positive inward).
  double depth_of(const Vec3& p_mm) const { return -(p_mm - centre_mm).dot(normal); }
  /// Distance of p from the axis (mm).
  double radial_of(const Vec3& p_mm) const {
    const Vec3 d = p_mm - centre_mm;
    return (d - d.dot(normal) * normal).norm();
  }
  /// The point at angle theta (rad, from u towards v) on the rim, at depth `depth_mm`.
  Vec3 rim_point(double theta, double at_depth_mm) const;
};

/// Tangent frame (u, v) of a unit normal, as described above.
std::pair<Vec3, Vec3> tangent_frame(const Vec3& normal);

/// Frame of `incision`, its centre projected onto the surface (within `tolerance_mm`). Throws
/// InputError when the centre is farther than that from the surface.
IncisionFrame incision_frame(const BodySurface& surface, const RoundIncision& incision, double tolerance_mm);

struct IncisionLinks {
  std::vector<CellFace> links;     ///< uncut links to cut (each once)
  std::vector<CellId> plug_cells;  ///< cells inside the cylinder above depth d
};

IncisionLinks round_incision_links(const LinkedVolume& volume, const IncisionFrame& frame, PlugHandling plug);

}  // namespace cleave
