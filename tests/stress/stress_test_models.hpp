#pragma once
// Models and designs shared by the stress tests.
#include <cmath>
#include <numbers>

#include "cleave/model/tissue_model.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave::test {

inline TissueModel builtin_model(const char* name, const ShapeResolution& resolution = {}) {
  return make_tissue_model(name, make_builtin_shape(name, resolution));
}

/// Axis of the built-in tube (x, y of the centre; mm) and its outer radius.
inline Vec3 tube_center(const TissueModel& m) {
  const GridSpec& g = m.volume.grid();
  return g.origin_mm + 0.5 * g.extent_mm();
}
inline double tube_outer_radius(const TissueModel& m) { return 0.5 * m.volume.grid().extent_mm().x(); }

/// A closed stroke around the tube's outer surface at height z (mm).
inline DesignStroke circumferential_stroke(const TissueModel& m, double z_mm, int segments = 36) {
  DesignStroke s;
  const Vec3 c = tube_center(m);
  const double r = tube_outer_radius(m);
  for (int i = 0; i <= segments; ++i) {
    const double a = 2.0 * std::numbers::pi * i / segments;
    s.points_mm.emplace_back(c.x() + r * std::cos(a), c.y() + r * std::sin(a), z_mm);
  }
  return s;
}

/// A straight stroke along the tube's axis on its outer surface at angle `angle` (rad).
inline DesignStroke axial_stroke(const TissueModel& m, double angle, double z0_mm, double z1_mm) {
  const Vec3 c = tube_center(m);
  const double r = tube_outer_radius(m);
  DesignStroke s;
  for (int i = 0; i <= 10; ++i) {
    const double z = z0_mm + (z1_mm - z0_mm) * i / 10.0;
    s.points_mm.emplace_back(c.x() + r * std::cos(angle), c.y() + r * std::sin(angle), z);
  }
  return s;
}

/// Circumferential unit direction at p around the tube's axis.
inline Vec3 circumferential(const TissueModel& m, const Vec3& p) {
  const Vec3 c = tube_center(m);
  return Vec3(-(p.y() - c.y()), p.x() - c.x(), 0.0).normalized();
}

}  // namespace cleave::test
