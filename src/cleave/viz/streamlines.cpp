#include "cleave/viz/streamlines.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "cleave/core/error.hpp"
#include "cleave/stress/surface_cells.hpp"

namespace cleave {
namespace {

/// Appends points from `seed` along +/- `start` until a stop condition (see header).
std::vector<Vec3> trace_one_way(const LinkedVolume& volume, std::span<const DirectionFrame> frames, const Vec3& seed,
                                Vec3 direction, const StreamlineOptions& options) {
  const double step = options.step_cells * volume.grid().cell_size_mm;
  const double min_cos = std::cos(options.max_turn_deg * std::numbers::pi / 180.0);
  const auto oriented = [&](const Vec3& p, const Vec3& previous, bool& ok) {
    const CellId c = volume.cell_containing(p);
    ok = c != kNone;
    if (!ok) return previous;
    Vec3 d = frames[static_cast<std::size_t>(c)].langer;
    if (d.dot(previous) < 0.0) d = -d;
    ok = d.dot(previous) >= min_cos;
    return d;
  };
  std::vector<Vec3> points;
  Vec3 p = seed;
  for (int s = 0; s < options.max_steps; ++s) {
    bool ok = false;
    const Vec3 d1 = oriented(p, direction, ok);
    if (!ok) break;
    const Vec3 d2 = oriented(p + 0.5 * step * d1, d1, ok);
    if (!ok) break;
    const Vec3 next = p + step * d2;
    if (volume.cell_containing(next) == kNone) break;
    points.push_back(next);
    p = next;
    direction = d2;
  }
  return points;
}

}  // namespace

std::vector<std::vector<Vec3>> trace_streamlines(const LinkedVolume& volume, std::span<const DirectionFrame> frames,
                                                 const StreamlineOptions& options) {
  if (frames.size() != static_cast<std::size_t>(volume.cell_count()))
    throw InputError(fmt::format("streamlines got {} frames; expected one per cell ({})", frames.size(), volume.cell_count()));
  if (options.seed_stride_cells < 1 || !(options.step_cells > 0.0) || options.max_steps < 1 ||
      !(options.max_turn_deg > 0.0 && options.max_turn_deg <= 180.0))
    throw InputError(fmt::format("streamline options (stride {}, step {} cells, {} steps, turn {} deg) out of range; expected "
                                 "stride >= 1, step > 0, steps >= 1, 0 < turn <= 180",
                                 options.seed_stride_cells, options.step_cells, options.max_steps, options.max_turn_deg));
  std::vector<std::vector<Vec3>> lines;
  const int stride = options.seed_stride_cells;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Vec3i& v = volume.cell_voxel(c);
    if (v.x() % stride != 0 || v.y() % stride != 0 || v.z() % stride != 0 || !is_boundary_cell(volume, c)) continue;
    const Vec3 seed = volume.cell_center_mm(c);
    const Vec3 d = frames[static_cast<std::size_t>(c)].langer;
    std::vector<Vec3> backward = trace_one_way(volume, frames, seed, -d, options);
    const std::vector<Vec3> forward = trace_one_way(volume, frames, seed, d, options);
    std::reverse(backward.begin(), backward.end());
    backward.push_back(seed);
    backward.insert(backward.end(), forward.begin(), forward.end());
    if (backward.size() >= 2) lines.push_back(std::move(backward));
  }
  return lines;
}

}  // namespace cleave
