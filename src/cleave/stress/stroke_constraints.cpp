#include "cleave/stress/stroke_constraints.hpp"

#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <map>

#include "cleave/core/error.hpp"
#include "cleave/stress/surface_cells.hpp"

namespace cleave {
namespace {

/// Samples per cell length along a stroke: spacing < half a cell, as the brief asks.
constexpr double kSamplesPerCell = 2.5;

std::string format_point(const Vec3& p) { return fmt::format("({:.6g}, {:.6g}, {:.6g})", p.x(), p.y(), p.z()); }

void check_stroke_shape(const DesignStroke& stroke, std::size_t index, const std::string& label) {
  if (stroke.points_mm.size() < 2)
    throw InputError(fmt::format("{} {} has {} point{}; expected at least two points", label, index,
                                 stroke.points_mm.size(), stroke.points_mm.size() == 1 ? "" : "s"));
  double length = 0;
  for (std::size_t i = 0; i < stroke.points_mm.size(); ++i) {
    if (!stroke.points_mm[i].allFinite())
      throw InputError(fmt::format("{} {} point {} is not finite; expected coordinates in mm", label, index, i));
    if (i > 0) length += (stroke.points_mm[i] - stroke.points_mm[i - 1]).norm();
  }
  if (!(length > 0.0))
    throw InputError(fmt::format("{} {} has zero length; expected at least two distinct points", label, index));
}

}  // namespace

double distance_to_surface_mm(const LinkedVolume& volume, const Vec3& p_mm) {
  double best = std::numeric_limits<double>::infinity();
  const double h = volume.grid().cell_size_mm;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (Face f = 0; f < kFaceCount; ++f)
      if (!volume.linked(c, f))
        best = std::min(best, (volume.cell_center_mm(c) + 0.5 * h * face_step(f).cast<double>() - p_mm).norm());
  return best;
}

std::vector<LineTarget> stroke_line_targets(const TissueModel& model, const std::vector<DesignStroke>& strokes,
                                            double tolerance_mm, const std::string& label) {
  const LinkedVolume& volume = model.volume;
  const double h = volume.grid().cell_size_mm;
  struct Accumulated {
    Mat3 sum = Mat3::Zero();
    int count = 0;
  };
  std::map<CellId, Accumulated> per_cell;
  for (std::size_t s = 0; s < strokes.size(); ++s) {
    const DesignStroke& stroke = strokes[s];
    check_stroke_shape(stroke, s, label);
    // Every drawn point must be usable: on the surface (within tolerance) or inside the body.
    for (std::size_t i = 0; i < stroke.points_mm.size(); ++i) {
      const Vec3& p = stroke.points_mm[i];
      if (stroke.placement == StrokePlacement::interior) {
        if (volume.cell_containing(p) == kNone)
          throw InputError(fmt::format("{} {} point {} at {} mm is outside the body; expected an interior stroke inside it",
                                       label, s, i, format_point(p)));
      } else if (snap_to_surface(volume, p, tolerance_mm).cell == kNone) {
        throw InputError(fmt::format("{} {} point {} at {} mm is {:.3g} mm from the body surface; expected within {:.3g} mm",
                                     label, s, i, format_point(p), distance_to_surface_mm(volume, p), tolerance_mm));
      }
    }
    for (std::size_t i = 0; i + 1 < stroke.points_mm.size(); ++i) {
      const Vec3 a = stroke.points_mm[i];
      const Vec3 b = stroke.points_mm[i + 1];
      const double length = (b - a).norm();
      if (length == 0.0) continue;
      const Vec3 t = (b - a) / length;
      const Mat3 line = t * t.transpose();
      const int samples = std::max(1, static_cast<int>(std::ceil(kSamplesPerCell * length / h)));
      for (int k = 0; k < samples; ++k) {
        // Midpoints of equal sub-segments: the same set of points when the stroke is reversed.
        const Vec3 p = a + (b - a) * ((k + 0.5) / samples);
        CellId cell = kNone;
        if (stroke.placement == StrokePlacement::interior) {
          cell = volume.cell_containing(p);
        } else {
          cell = snap_to_surface(volume, p, tolerance_mm).cell;
        }
        if (cell == kNone) continue;  // a sample between two valid points that leaves the body
        Accumulated& acc = per_cell[cell];
        acc.sum += line;
        ++acc.count;
      }
    }
  }
  std::vector<LineTarget> targets;
  targets.reserve(per_cell.size());
  for (const auto& [cell, acc] : per_cell) targets.push_back({cell, acc.sum / acc.count});
  return targets;
}

std::vector<LineTarget> surface_normal_targets(const TissueModel& model) {
  std::vector<LineTarget> targets;
  for (CellId c : boundary_cells(model.volume))
    if (const auto n = surface_normal(model, c)) targets.push_back({c, *n * n->transpose()});
  return targets;
}

}  // namespace cleave
