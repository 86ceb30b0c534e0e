#include "cleave/viz/wound_measures.hpp"

#include <algorithm>

#include "cleave/fem/hex8_element.hpp"
#include "cleave/viz/displacement_at_point.hpp"

namespace cleave {
namespace {

constexpr double kEndExclusionCells = 1.0;

Vec3 deformed(const LinkedVolume& volume, std::span<const Vec3> u, CellId c, int corner) {
  const VertexId v = volume.corner_vertex(c, corner);
  return volume.vertex_position_mm(v) + u[static_cast<std::size_t>(v)];
}

double quad_area(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // corners in face_corners order (a, b, c, d) form the quad with diagonals a-d and b-c
  return 0.5 * (d - a).cross(c - b).norm();
}

}  // namespace

WoundWidth scalpel_wound_width(const LinkedVolume& volume, std::span<const Vec3> displacement_mm,
                               const SweptPath& path) {
  WoundWidth out;
  const std::size_t n = path.skin_mm.size();
  out.width_mm.assign(n, 0.0);
  const double end_mm = kEndExclusionCells * volume.grid().cell_size_mm;
  double along = 0;
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) along += (path.skin_mm[i] - path.skin_mm[i - 1]).norm();
    if (along < end_mm || path.length_mm - along < end_mm) continue;
    const Vec3 ahead = path.skin_mm[std::min(i + 1, n - 1)] - path.skin_mm[i > 0 ? i - 1 : 0];
    const Vec3 side = ahead.cross(path.normal[i]).normalized();
    const Vec3 x = path.skin_mm[i];
    const auto on = [&](double sign) {
      return [&volume, &x, &side, sign](CellId c) { return sign * (volume.cell_center_mm(c) - x).dot(side) > 0; };
    };
    const auto plus = displacement_at_point(volume, displacement_mm, x, on(1.0));
    const auto minus = displacement_at_point(volume, displacement_mm, x, on(-1.0));
    if (!plus || !minus) continue;
    const double w = (*plus - *minus).dot(side);
    out.width_mm[i] = w;
    out.max_mm = out.samples == 0 ? w : std::max(out.max_mm, w);
    sum += w;
    ++out.samples;
  }
  out.mean_mm = out.samples > 0 ? sum / out.samples : 0;
  return out;
}

FlapChange flap_change(const LinkedVolume& volume, std::span<const Vec3> displacement_mm, const FlapRegion& region) {
  FlapChange out;
  const double h = volume.grid().cell_size_mm;
  const std::vector<Vec3> zero(displacement_mm.size(), Vec3::Zero());
  for (const CellId c : region.cells) {
    for (Face f = 0; f < kFaceCount; ++f) {
      if (volume.neighbor(c, f) != kNone) continue;
      if (face_step(f).cast<double>().dot(region.normal) <= 0) continue;
      const auto k = face_corners(f);
      out.skin_area_before_mm2 += quad_area(deformed(volume, zero, c, k[0]), deformed(volume, zero, c, k[1]),
                                            deformed(volume, zero, c, k[2]), deformed(volume, zero, c, k[3]));
      out.skin_area_after_mm2 +=
          quad_area(deformed(volume, displacement_mm, c, k[0]), deformed(volume, displacement_mm, c, k[1]),
                    deformed(volume, displacement_mm, c, k[2]), deformed(volume, displacement_mm, c, k[3]));
    }
    Vec24 u;
    for (int a = 0; a < kCornerCount; ++a)
      u.segment<3>(3 * a) = displacement_mm[static_cast<std::size_t>(volume.corner_vertex(c, a))];
    out.volume_before_mm3 += h * h * h;
    out.volume_after_mm3 += h * h * h * hex8_center_deformation_gradient(u, h).determinant();
  }
  const auto percent = [](double before, double after) { return before > 0 ? (after - before) / before * 100 : 0.0; };
  out.skin_area_change_percent = percent(out.skin_area_before_mm2, out.skin_area_after_mm2);
  out.volume_change_percent = percent(out.volume_before_mm3, out.volume_after_mm3);
  return out;
}

}  // namespace cleave
