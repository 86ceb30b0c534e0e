#include "cleave/surface/surface_vertex_placement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cleave {
namespace {

/// Newton steps towards the zero level set (the field is near a distance, so 2 suffice).
constexpr int kNewtonSteps = 3;
/// Gradient by central differences over this fraction of a cell.
constexpr double kGradientStepCells = 0.25;
/// Below this squared gradient norm (per mm^2) the field gives no direction; the vertex stays.
constexpr double kMinGradientSquared = 1e-8;

}  // namespace

double SurfaceField::sample_mm(const Vec3& p_mm) const {
  const GridSpec& g = *grid;
  const Vec3 t_grid = (p_mm - g.origin_mm) / g.cell_size_mm;
  Vec3i base;
  Vec3 t;
  for (int a = 0; a < 3; ++a) {
    const double clamped = std::clamp(t_grid[a], 0.0, static_cast<double>(g.dims[a]));
    base[a] = std::min(static_cast<int>(std::floor(clamped)), g.dims[a] - 1);
    t[a] = clamped - base[a];
  }
  double value = 0;
  for (int c = 0; c < kCornerCount; ++c) {
    const Vec3i o = corner_offset(c);
    const double w = trilinear_corner_weight(c, t);
    value += w * static_cast<double>((*corner_mm)[static_cast<size_t>(g.corner_index(base + o))]);
  }
  return value;
}

std::vector<float> mask_distance_field(const LabelVolume& labels) {
  const GridSpec& g = labels.grid;
  std::vector<float> field(static_cast<size_t>(g.corner_count()));
  for (int z = 0; z <= g.dims.z(); ++z)
    for (int y = 0; y <= g.dims.y(); ++y)
      for (int x = 0; x <= g.dims.x(); ++x) {
        const Vec3i corner{x, y, z};
        int inside = 0;
        for (int k = 0; k < kCornerCount; ++k) inside += labels.at(corner - corner_offset(k)) != 0 ? 1 : 0;
        const double occupancy = inside / static_cast<double>(kCornerCount);
        field[static_cast<size_t>(g.corner_index(corner))] = static_cast<float>(g.cell_size_mm * (1.0 - 2.0 * occupancy));
      }
  return field;
}

VertexPlacement place_fan_vertex(const LinkedVolume& volume, const SurfaceField& field, const Vec3i& g,
                                 const CornerFan& fan) {
  const GridSpec& grid = volume.grid();
  const double h = grid.cell_size_mm;
  const Vec3 corner_mm = grid.corner_position_mm(g);
  bool outside = false;
  Vec3 free_axes = Vec3::Ones();
  for (int i = 0; i < fan.count; ++i) {
    const CellFace& f = fan.faces[static_cast<size_t>(i)];
    if (volume.neighbor(f.cell, f.face) == kNone) outside = true;
    else free_axes[f.face / 2] = 0;
  }

  Vec3 p = corner_mm;
  if (outside && free_axes.sum() > 0) {
    const double max_shift = field.max_shift_cells * h;
    const double step = kGradientStepCells * h;
    for (int iteration = 0; iteration < kNewtonSteps; ++iteration) {
      const double value = field.sample_mm(p);
      Vec3 gradient = Vec3::Zero();
      for (int a = 0; a < 3; ++a) {
        if (free_axes[a] == 0) continue;
        Vec3 d = Vec3::Zero();
        d[a] = step;
        gradient[a] = (field.sample_mm(p + d) - field.sample_mm(p - d)) / (2 * step);
      }
      const double norm2 = gradient.squaredNorm();
      if (!(norm2 > kMinGradientSquared) || !std::isfinite(value)) break;
      p -= (value / norm2) * gradient;
      p = p.cwiseMax(corner_mm - Vec3::Constant(max_shift)).cwiseMin(corner_mm + Vec3::Constant(max_shift));
    }
  }

  // Embed in the fan's cell whose box is closest to p (the first such cell on ties).
  VertexPlacement placement;
  placement.position_mm = p;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < fan.count; ++i) {
    const CellId c = fan.faces[static_cast<size_t>(i)].cell;
    const Vec3 lo = grid.corner_position_mm(volume.cell_voxel(c));
    const Vec3 outside_by = (lo - p).cwiseMax(p - (lo + Vec3::Constant(h))).cwiseMax(0.0);
    const double d = outside_by.squaredNorm();
    if (d < best) {
      best = d;
      placement.cell = c;
      placement.xi = (p - lo) / h;
    }
  }
  return placement;
}

}  // namespace cleave
