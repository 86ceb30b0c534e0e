#include "cleave/cut/round_incision_links.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/cut/links_crossing_surface.hpp"

namespace cleave {
namespace {

constexpr double kAboveSkinCells = 1.0;  ///< the wall starts this many cells above the tangent plane
constexpr Face kPositiveFaces[] = {1, 3, 5};

/// Parameters s in [0, 1] where segment a + s (b - a) meets the infinite cylinder of the frame.
std::vector<double> cylinder_crossings(const IncisionFrame& frame, const Vec3& a, const Vec3& b) {
  const auto radial = [&](const Vec3& d) { return Vec3(d - d.dot(frame.normal) * frame.normal); };
  const Vec3 w0 = radial(a - frame.centre_mm);
  const Vec3 wd = radial(b - a);
  const double qa = wd.squaredNorm();
  const double qb = 2 * w0.dot(wd);
  const double qc = w0.squaredNorm() - frame.radius_mm * frame.radius_mm;
  std::vector<double> out;
  if (qa <= 0) return out;
  const double disc = qb * qb - 4 * qa * qc;
  if (disc < 0) return out;
  const double root = std::sqrt(disc);
  for (const double s : {(-qb - root) / (2 * qa), (-qb + root) / (2 * qa)})
    if (s >= 0 && s <= 1) out.push_back(s);
  return out;
}

}  // namespace

Vec3 IncisionFrame::rim_point(double theta, double at_depth_mm) const {
  return centre_mm + radius_mm * (std::cos(theta) * tangent_u + std::sin(theta) * tangent_v) - at_depth_mm * normal;
}

std::pair<Vec3, Vec3> tangent_frame(const Vec3& normal) {
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(normal[a]) < std::abs(normal[axis])) axis = a;
  const Vec3 u = (Vec3::Unit(axis) - normal.dot(Vec3::Unit(axis)) * normal).normalized();
  return {u, normal.cross(u)};
}

IncisionFrame incision_frame(const BodySurface& surface, const RoundIncision& incision, double tolerance_mm) {
  const auto s = surface.project(incision.centre_mm, tolerance_mm);
  if (!s)
    throw InputError(fmt::format("incision centre ({:.3g}, {:.3g}, {:.3g}) mm is {:.3g} mm off the body's surface; "
                                 "expected a point within {:.3g} mm of it",
                                 incision.centre_mm.x(), incision.centre_mm.y(), incision.centre_mm.z(),
                                 surface.distance_mm(incision.centre_mm), tolerance_mm));
  IncisionFrame f;
  f.centre_mm = s->position_mm;
  f.normal = s->normal;
  std::tie(f.tangent_u, f.tangent_v) = tangent_frame(f.normal);
  f.radius_mm = incision.radius_mm;
  f.depth_mm = incision.depth_mm;
  return f;
}

IncisionLinks round_incision_links(const LinkedVolume& volume, const IncisionFrame& frame, PlugHandling plug) {
  const GridSpec& grid = volume.grid();
  const double h = grid.cell_size_mm;
  const double above = kAboveSkinCells * h;
  const double reach = std::hypot(frame.radius_mm + h, std::max(frame.depth_mm, above) + h);
  const Vec3i v_lo = grid.voxel_of(frame.centre_mm - Vec3::Constant(reach)).cwiseMax(Vec3i::Zero());
  const Vec3i v_hi = grid.voxel_of(frame.centre_mm + Vec3::Constant(reach)).cwiseMin(grid.dims - Vec3i::Ones());
  const auto within_depth = [&](const Vec3& p) {
    const double d = frame.depth_of(p);
    return d >= -above && d <= frame.depth_mm;
  };
  IncisionLinks out;
  for (int z = v_lo.z(); z <= v_hi.z(); ++z)
    for (int y = v_lo.y(); y <= v_hi.y(); ++y)
      for (int x = v_lo.x(); x <= v_hi.x(); ++x) {
        const CellId c = volume.cell_at_voxel({x, y, z});
        if (c == kNone) continue;
        const Vec3 a = volume.cell_center_mm(c);
        if (frame.radial_of(a) < frame.radius_mm && within_depth(a)) out.plug_cells.push_back(c);
        for (const Face f : kPositiveFaces) {
          const CellId n = volume.neighbor(c, f);
          if (n == kNone || volume.is_cut(c, f)) continue;
          const Vec3 b = volume.cell_center_mm(n);
          for (const double s : cylinder_crossings(frame, a, b))
            if (within_depth(a + s * (b - a))) {
              out.links.push_back({c, f});
              break;
            }
        }
      }
  if (plug == PlugHandling::remove) {
    std::vector<std::uint8_t> in_plug(static_cast<std::size_t>(volume.cell_count()), 0);
    for (const CellId c : out.plug_cells) in_plug[static_cast<std::size_t>(c)] = 1;
    const auto in_a = [&](CellId c) { return in_plug[static_cast<std::size_t>(c)] != 0; };
    const std::vector<CellFace> rest =
        links_leaving(volume, out.plug_cells, in_a, [](CellId, CellId) { return true; });
    out.links.insert(out.links.end(), rest.begin(), rest.end());
  }
  return out;
}

}  // namespace cleave
