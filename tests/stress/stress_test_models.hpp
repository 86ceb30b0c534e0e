#pragma once
// Models and designs shared by the stress tests.
#include <cmath>
#include <numbers>
#include <vector>

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

/// Point on the abdomen's skin above (x, z): the top of the body found by a vertical ray.
inline Vec3 skin_point(const TissueModel& m, double x_mm, double z_mm) {
  const LinkedVolume& v = m.volume;
  const double step = 0.1 * v.grid().cell_size_mm;
  double y = v.grid().origin_mm.y() + v.grid().extent_mm().y();
  while (y > v.grid().origin_mm.y() && v.cell_containing(Vec3(x_mm, y, z_mm)) == kNone) y -= step;
  return {x_mm, y + 0.5 * step, z_mm};
}

/// The `cleave demo` design on the abdomen: three strokes along x over the skin (at 20, 50 and
/// 80 % of its length), four control points of 20 kPa along / 10 kPa across.
inline StressDesign abdomen_demo_design(const TissueModel& m) {
  StressDesign d;
  const Vec3 extent = m.volume.grid().extent_mm();
  const double w = extent.x(), l = extent.z();
  for (const double z : {0.2 * l, 0.5 * l, 0.8 * l}) {
    DesignStroke s;
    for (int i = 1; i <= 9; ++i) s.points_mm.push_back(skin_point(m, 0.1 * i * w, z));
    d.strokes.push_back(s);
  }
  for (const double x : {0.3 * w, 0.7 * w})
    for (const double z : {0.3 * l, 0.7 * l}) d.control_points.push_back({skin_point(m, x, z), 20, 10});
  return d;
}

/// Vertices of the abdomen's rim: a band `rim_mm` wide along its four side edges (the demo's held wall).
inline std::vector<VertexId> abdomen_rim_vertices(const TissueModel& m, double rim_mm = 5.0) {
  const Vec3 e = m.volume.grid().extent_mm();
  const Vec3 o = m.volume.grid().origin_mm;
  std::vector<VertexId> out;
  for (VertexId v = 0; v < m.volume.vertex_count(); ++v) {
    const Vec3 p = m.volume.vertex_position_mm(v) - o;
    if (p.x() <= rim_mm || p.x() >= e.x() - rim_mm || p.z() <= rim_mm || p.z() >= e.z() - rim_mm) out.push_back(v);
  }
  return out;
}

}  // namespace cleave::test
