#pragma once
// The body's surface as the cut domain sees it: points, outward normals, projection of a point
// onto the surface, and the body's thickness under a surface point. Built from the tissue model's
// voxel labels and (when present) its corner signed distances:
//   - with a distance field, the surface is its zero level set (trilinear interpolation of the
//     corner distances); normals are its normalized gradient and projection is Newton's method
//     along the gradient;
//   - without one, the surface is the set of boundary voxel faces (faces with no neighbouring
//     cell); normals are those of the closest boundary face (the mean over faces within two cells
//     that face the same way, so a corner or an edge of the body does not tilt them),
//     and projection goes to the closest point of the boundary face with the closest centre.
//
//   BodySurface surface(model);
//   std::optional<SurfacePoint> s = surface.project(p_mm);   // nullopt: farther than the tolerance
//   surface.samples(SurfaceSide::outer)                       // one point per boundary voxel face
//
// "Outer" side: a surface point whose outward normal points away from the centre of the body's
// bounding box. For the shells cleave models (tube, abdomen) this is the skin and excludes the
// inner surface; for a plate it is both faces. "Inner" side: every other surface point (the
// tube's bore, the abdominal wall's deep face lying on the body beneath; none for a plate).
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "cleave/model/tissue_model.hpp"

namespace cleave {

struct SurfacePoint {
  Vec3 position_mm = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  ///< outward unit normal
};

enum class SurfaceSide {
  outer,  ///< facing away from the bounding-box centre (the skin of a shell)
  inner,  ///< facing towards it (the deep face of a shell)
  all,    ///< every boundary face
};

class BodySurface {
 public:
  /// Keeps a reference to `model` (it must outlive this object). Cuts made later do not change
  /// the surface this object describes (it is the uncut body's surface).
  explicit BodySurface(const TissueModel& model);

  /// Closest surface point to p (mm), or nullopt when p lies farther than `tolerance_mm` from
  /// the surface.
  std::optional<SurfacePoint> project(const Vec3& p_mm, double tolerance_mm) const;
  /// Distance from p to the surface (mm, >= 0; approximate to a fraction of a cell).
  double distance_mm(const Vec3& p_mm) const;
  /// Outward unit normal at (or near) surface point p.
  Vec3 normal_at(const Vec3& p_mm) const;
  /// One surface point per boundary voxel face on `side`, at the face centre projected onto the
  /// surface, in a deterministic order.
  std::vector<SurfacePoint> samples(SurfaceSide side) const;
  /// The side (outer or inner) that surface point p lies on, by its outward normal.
  SurfaceSide side_of(const SurfacePoint& p) const;
  /// Distance (mm) from surface point p along unit direction `inward` until the body is left
  /// (marching in quarter-cell steps from the first point inside); 0 when the ray never enters.
  double thickness_mm(const Vec3& p_mm, const Vec3& inward) const;
  /// True when p lies inside an active cell.
  bool inside(const Vec3& p_mm) const { return model_.volume.cell_containing(p_mm) != kNone; }
  /// Cell edge length h (mm).
  double cell_size_mm() const { return model_.volume.grid().cell_size_mm; }
  const TissueModel& model() const { return model_; }

 private:
  double field_mm(const Vec3& p_mm) const;
  Vec3 field_gradient(const Vec3& p_mm) const;
  std::size_t closest_face(const Vec3& p_mm) const;
  /// Closest point on the closest boundary face (by centre distance).
  Vec3 onto_closest_face(const Vec3& p_mm) const;

  const TissueModel& model_;
  bool has_field_ = false;
  Vec3 body_centre_mm_ = Vec3::Zero();
  std::vector<Vec3> face_centre_mm_;  ///< per boundary face
  std::vector<Vec3> face_normal_;     ///< per boundary face (axis aligned)
};

}  // namespace cleave
