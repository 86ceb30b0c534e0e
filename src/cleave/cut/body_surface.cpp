#include "cleave/cut/body_surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cleave {
namespace {

constexpr int kNewtonSteps = 12;
constexpr double kNewtonStopCells = 1e-6;      ///< stop when |phi| < this many cells
constexpr double kNormalRadiusCells = 2.0;     ///< face normals averaged within this radius (no field)
constexpr double kThicknessStepCells = 0.25;   ///< marching step of thickness_mm
constexpr int kBisectionSteps = 30;

Vec3 face_normal(Face f) { return face_step(f).cast<double>(); }

}  // namespace

BodySurface::BodySurface(const TissueModel& model) : model_(model) {
  const LinkedVolume& volume = model.volume;
  const GridSpec& grid = volume.grid();
  has_field_ = model.labels.has_distance() && model.labels.grid.dims == grid.dims;
  const auto [lo, hi] = model.bounding_box_mm();
  body_centre_mm_ = 0.5 * (lo + hi);
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (Face f = 0; f < kFaceCount; ++f)
      if (volume.neighbor(c, f) == kNone) {
        face_centre_mm_.push_back(volume.cell_center_mm(c) + 0.5 * grid.cell_size_mm * face_normal(f));
        face_normal_.push_back(face_normal(f));
      }
}

double BodySurface::field_mm(const Vec3& p_mm) const {
  const GridSpec& grid = model_.labels.grid;
  const Vec3 g = (p_mm - grid.origin_mm) / grid.cell_size_mm;
  const Vec3 clamped = g.cwiseMax(Vec3::Zero()).cwiseMin(grid.dims.cast<double>());
  const double outside_mm = (g - clamped).norm() * grid.cell_size_mm;
  Vec3i base = clamped.array().floor().cast<int>();
  base = base.cwiseMin(grid.dims - Vec3i::Ones()).cwiseMax(Vec3i::Zero());
  const Vec3 t = clamped - base.cast<double>();
  double value = 0;
  for (int c = 0; c < kCornerCount; ++c) {
    const Vec3i o = corner_offset(c);
    const double w = trilinear_corner_weight(c, t);
    value += w * static_cast<double>(model_.labels.corner_distance_mm[static_cast<std::size_t>(grid.corner_index(base + o))]);
  }
  return value + outside_mm;
}

Vec3 BodySurface::field_gradient(const Vec3& p_mm) const {
  const double step = 0.25 * cell_size_mm();
  Vec3 g;
  for (int a = 0; a < 3; ++a) {
    const Vec3 d = step * Vec3::Unit(a);
    g[a] = (field_mm(p_mm + d) - field_mm(p_mm - d)) / (2 * step);
  }
  return g;
}

std::size_t BodySurface::closest_face(const Vec3& p_mm) const {
  std::size_t best = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < face_centre_mm_.size(); ++i) {
    const double d2 = (face_centre_mm_[i] - p_mm).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  return best;
}

Vec3 BodySurface::normal_at(const Vec3& p_mm) const {
  if (has_field_) {
    const Vec3 g = field_gradient(p_mm);
    if (g.norm() > 0) return g.normalized();
  }
  if (face_normal_.empty()) return Vec3::UnitZ();
  const Vec3 nearest = face_normal_[closest_face(p_mm)];
  const double radius = kNormalRadiusCells * cell_size_mm();
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 0; i < face_centre_mm_.size(); ++i)
    if ((face_centre_mm_[i] - p_mm).norm() <= radius && face_normal_[i].dot(nearest) > 0) sum += face_normal_[i];
  return sum.norm() > 0 ? Vec3(sum.normalized()) : nearest;
}

Vec3 BodySurface::onto_closest_face(const Vec3& p_mm) const {
  const std::size_t i = closest_face(p_mm);
  const Vec3& c = face_centre_mm_[i];
  const Vec3& n = face_normal_[i];
  const double half = 0.5 * cell_size_mm();
  Vec3 q = p_mm - (p_mm - c).dot(n) * n;  // onto the face's plane, then clamped to the face
  for (int a = 0; a < 3; ++a)
    if (n[a] == 0) q[a] = std::clamp(q[a], c[a] - half, c[a] + half);
  return q;
}

double BodySurface::distance_mm(const Vec3& p_mm) const {
  if (has_field_) return std::abs(field_mm(p_mm));
  if (face_centre_mm_.empty()) return std::numeric_limits<double>::infinity();
  return (onto_closest_face(p_mm) - p_mm).norm();
}

std::optional<SurfacePoint> BodySurface::project(const Vec3& p_mm, double tolerance_mm) const {
  if (face_centre_mm_.empty()) return std::nullopt;
  Vec3 q = p_mm;
  if (has_field_) {
    for (int i = 0; i < kNewtonSteps; ++i) {
      const double phi = field_mm(q);
      if (std::abs(phi) < kNewtonStopCells * cell_size_mm()) break;
      const Vec3 g = field_gradient(q);
      if (!(g.squaredNorm() > 0)) break;
      q -= phi * g / g.squaredNorm();
    }
    if (std::abs(field_mm(q)) > 0.1 * cell_size_mm()) q = onto_closest_face(p_mm);
  } else {
    q = onto_closest_face(p_mm);
  }
  if ((q - p_mm).norm() > tolerance_mm || !std::isfinite(q.squaredNorm())) return std::nullopt;
  return SurfacePoint{q, normal_at(q)};
}

std::vector<SurfacePoint> BodySurface::samples(SurfaceSide side) const {
  std::vector<SurfacePoint> out;
  out.reserve(face_centre_mm_.size());
  for (std::size_t i = 0; i < face_centre_mm_.size(); ++i) {
    const auto s = project(face_centre_mm_[i], cell_size_mm());
    const SurfacePoint p = s ? *s : SurfacePoint{face_centre_mm_[i], face_normal_[i]};
    if (side != SurfaceSide::all && side_of(p) != side) continue;
    out.push_back(p);
  }
  return out;
}

SurfaceSide BodySurface::side_of(const SurfacePoint& p) const {
  return p.normal.dot(p.position_mm - body_centre_mm_) > 0 ? SurfaceSide::outer : SurfaceSide::inner;
}

double BodySurface::thickness_mm(const Vec3& p_mm, const Vec3& inward) const {
  const double step = kThicknessStepCells * cell_size_mm();
  const double reach = model_.size_mm();
  double s = 0;
  while (s <= reach && !inside(p_mm + s * inward)) s += step;
  if (s > reach) return 0;
  while (s <= reach && inside(p_mm + s * inward)) s += step;
  double in = s - step, out = s;  // the exit lies between; bisect to a tiny fraction of a cell
  for (int i = 0; i < kBisectionSteps; ++i) {
    const double mid = 0.5 * (in + out);
    (inside(p_mm + mid * inward) ? in : out) = mid;
  }
  return 0.5 * (in + out);
}

}  // namespace cleave
