#include "cleave/cut/links_crossing_surface.hpp"

#include <algorithm>
#include <cmath>

namespace cleave {
namespace {

/// Relative slack of the inclusive tests (barycentric coordinates and segment parameter).
constexpr double kTouchSlack = 1e-9;
constexpr Face kPositiveFaces[] = {1, 3, 5};

}  // namespace

bool segment_crosses_triangle(const Vec3& a, const Vec3& b, const Triangle& t) {
  const Vec3 dir = b - a;
  const Vec3 e1 = t[1] - t[0];
  const Vec3 e2 = t[2] - t[0];
  const Vec3 p = dir.cross(e2);
  const double det = e1.dot(p);
  const double scale = dir.norm() * e1.norm() * e2.norm();
  if (!(scale > 0) || std::abs(det) <= kTouchSlack * scale) return false;  // parallel or degenerate
  const double inv = 1.0 / det;
  const Vec3 s = a - t[0];
  const double u = s.dot(p) * inv;
  if (u < -kTouchSlack || u > 1 + kTouchSlack) return false;
  const Vec3 q = s.cross(e1);
  const double v = dir.dot(q) * inv;
  if (v < -kTouchSlack || u + v > 1 + kTouchSlack) return false;
  const double param = e2.dot(q) * inv;
  return param >= -kTouchSlack && param <= 1 + kTouchSlack;
}

std::vector<CellFace> links_crossing_triangles(const LinkedVolume& volume, std::span<const Triangle> triangles) {
  const GridSpec& grid = volume.grid();
  std::vector<CellFace> out;
  for (const Triangle& t : triangles) {
    Vec3 lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
    Vec3 hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
    // A crossing segment has its lower cell's centre within one cell of the triangle's box.
    const Vec3i v_lo = grid.voxel_of(lo - Vec3::Constant(grid.cell_size_mm)).cwiseMax(Vec3i::Zero());
    const Vec3i v_hi = grid.voxel_of(hi + Vec3::Constant(grid.cell_size_mm)).cwiseMin(grid.dims - Vec3i::Ones());
    for (int z = v_lo.z(); z <= v_hi.z(); ++z)
      for (int y = v_lo.y(); y <= v_hi.y(); ++y)
        for (int x = v_lo.x(); x <= v_hi.x(); ++x) {
          const CellId c = volume.cell_at_voxel({x, y, z});
          if (c == kNone) continue;
          for (const Face f : kPositiveFaces) {
            const CellId n = volume.neighbor(c, f);
            if (n == kNone || volume.is_cut(c, f)) continue;
            if (segment_crosses_triangle(volume.cell_center_mm(c), volume.cell_center_mm(n), t)) out.push_back({c, f});
          }
        }
  }
  std::sort(out.begin(), out.end(), [](const CellFace& l, const CellFace& r) {
    return l.cell != r.cell ? l.cell < r.cell : l.face < r.face;
  });
  out.erase(std::unique(out.begin(), out.end(),
                        [](const CellFace& l, const CellFace& r) { return l.cell == r.cell && l.face == r.face; }),
            out.end());
  return out;
}

}  // namespace cleave
