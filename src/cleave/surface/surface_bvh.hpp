#pragma once
// Picking on the render surface: the first surface point along a ray (clicks in the studio) and
// the closest surface point to a point (snapping strokes), accelerated by a bounding volume
// hierarchy over the triangles (binary, median split on the longest axis, up to 4 triangles per
// leaf). Building costs O(T log T) (a few ms for 100,000 triangles); a query visits O(log T) nodes.
//
//   SurfaceBvh bvh(surface, positions);              // positions: reference or deformed (mm)
//   if (auto hit = bvh.pick(eye_mm, direction)) use(hit->point_mm, hit->cell);
//   auto snap = bvh.closest_point(p_mm);
//
// The hierarchy copies the triangle corners, so it stays valid when `positions` changes; build a
// new one after the surface or the positions change.
#include <optional>
#include <vector>

#include "cleave/surface/render_surface.hpp"

namespace cleave {

struct SurfaceHit {
  Vec3 point_mm = Vec3::Zero();
  std::int32_t triangle = kNone;  ///< index into RenderSurface::triangles
  CellId cell = kNone;            ///< the cell of the boundary face the triangle came from
  Vec3 normal = Vec3::UnitZ();    ///< outward unit normal of the triangle
  double distance_mm = 0;         ///< along the ray (pick) or to the query point (closest_point)
};

class SurfaceBvh {
 public:
  /// `positions_mm` has one entry per surface vertex. Throws InputError when it does not.
  SurfaceBvh(const RenderSurface& surface, const std::vector<Vec3>& positions_mm);

  /// First triangle facing the ray (normal against `direction`) hit at distance >= 0 from
  /// `origin_mm`; `direction` need not be unit length. nullopt when the ray misses or
  /// `direction` is zero.
  std::optional<SurfaceHit> pick(const Vec3& origin_mm, const Vec3& direction) const;
  /// Closest point of the surface to `point_mm`; nullopt only for an empty surface.
  std::optional<SurfaceHit> closest_point(const Vec3& point_mm) const;

 private:
  struct Node {
    Vec3 lo, hi;
    std::int32_t first = 0;  ///< leaf: first entry in order_; inner: index of the left child
    std::int32_t count = 0;  ///< leaf: number of triangles; inner: 0 (right child = left + 1)
  };
  /// Fills node `node` (already allocated) with triangles order_[first, first + count).
  void build(std::int32_t node, std::int32_t first, std::int32_t count);
  SurfaceHit hit_of(std::int32_t t, const Vec3& point_mm, double distance_mm) const;

  std::vector<std::array<Vec3, 3>> corners_;  ///< per triangle
  std::vector<CellId> cell_;                  ///< per triangle
  std::vector<std::int32_t> order_;           ///< triangle indices, grouped by leaf
  std::vector<Node> nodes_;
};

/// One-off queries (build a SurfaceBvh for repeated ones).
std::optional<SurfaceHit> pick_surface(const RenderSurface& surface, const std::vector<Vec3>& positions_mm,
                                       const Vec3& ray_origin_mm, const Vec3& ray_direction);
std::optional<SurfaceHit> closest_surface_point(const RenderSurface& surface, const std::vector<Vec3>& positions_mm,
                                                const Vec3& point_mm);

}  // namespace cleave
