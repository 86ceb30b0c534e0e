#pragma once
// Round incisions placed evenly over the surface or a region of it (paper section 5: "a set of
// small, round incisions distributed over the surface"): Poisson-disk (blue-noise) sampling by
// dart throwing over the surface samples in a seeded random order; a candidate is accepted when
// no accepted centre lies closer than the spacing, the whole rim lies on the surface and the body
// is at least the depth thick under it.
//
//   IncisionPattern p;  p.radius_mm = 6;  p.depth_mm = 5;  p.spacing_mm = 25;
//   p.region = IncisionRegion::sphere({0, 80, 100}, 60);
//   std::vector<RoundIncision> incisions = place_incisions(surface, p);
//
// Errors (InputError): radius below one cell, depth not positive, spacing below the diameter plus
// one cell (incisions would merge), no place in the region, or fewer places than `count` asks.
#include <cstdint>
#include <optional>
#include <vector>

#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/cut_requests.hpp"

namespace cleave {

struct IncisionRegion {
  enum class Kind { whole_surface, box, sphere } kind = Kind::whole_surface;
  Vec3 lo_mm = Vec3::Zero();      ///< box corners (inclusive)
  Vec3 hi_mm = Vec3::Zero();
  Vec3 centre_mm = Vec3::Zero();  ///< sphere
  double radius_mm = 0;

  static IncisionRegion box(const Vec3& lo, const Vec3& hi) { return {Kind::box, lo, hi, Vec3::Zero(), 0}; }
  static IncisionRegion sphere(const Vec3& c, double r) { return {Kind::sphere, Vec3::Zero(), Vec3::Zero(), c, r}; }
  bool contains(const Vec3& p_mm) const;
};

struct IncisionPattern {
  double radius_mm = 0;
  double depth_mm = 0;
  double spacing_mm = 0;          ///< least distance between two incision centres
  std::optional<int> count;       ///< exactly this many (error if fewer fit); nullopt = as many as fit
  IncisionRegion region;
  SurfaceSide side = SurfaceSide::outer;
  PlugHandling plug = PlugHandling::remove;
  std::uint32_t seed = 1;         ///< same seed, same model -> same placement
};

std::vector<RoundIncision> place_incisions(const BodySurface& surface, const IncisionPattern& pattern);

}  // namespace cleave
