#include "cleave/viz/cut_face_colouring.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cleave/viz/nearest_point_index.hpp"

namespace cleave {
namespace {

/// The surface samples of one side with an index for their nearest one.
class SampleLookup {
 public:
  SampleLookup(std::vector<SurfacePoint> samples, double bucket_mm)
      : samples_(std::move(samples)), index_(positions(samples_), bucket_mm) {}
  bool empty() const { return samples_.empty(); }

  /// Distance from p to the tangent plane of the nearest sample: exact on a flat or gently
  /// curved surface, where the distance to the nearest sample point would overestimate by up to
  /// half a cell (samples are face centres). Infinite without samples.
  double distance(const Vec3& p) const {
    const std::size_t i = index_.nearest(p);
    if (i == NearestPointIndex::npos) return std::numeric_limits<double>::infinity();
    const SurfacePoint& s = samples_[i];
    return std::abs(s.normal.dot(p - s.position_mm));
  }

 private:
  static std::vector<Vec3> positions(const std::vector<SurfacePoint>& samples) {
    std::vector<Vec3> out;
    out.reserve(samples.size());
    for (const SurfacePoint& s : samples) out.push_back(s.position_mm);
    return out;
  }
  std::vector<SurfacePoint> samples_;
  NearestPointIndex index_;
};

}  // namespace

std::vector<CellFace> cut_faces(const LinkedVolume& volume) {
  std::vector<CellFace> out;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (Face f = 0; f < kFaceCount; ++f)
      if (volume.neighbor(c, f) != kNone && volume.is_cut(c, f)) out.push_back({c, f});
  return out;
}

double released_traction_kPa(const Vec6& stress_kPa, const Vec3& normal) { return (from_voigt(stress_kPa) * normal).norm(); }

std::array<float, 3> red_blue(double value, double lo, double hi) {
  const double t = hi > lo ? std::clamp((value - lo) / (hi - lo), 0.0, 1.0) : 1.0;
  return {static_cast<float>(t), 0.0f, static_cast<float>(1.0 - t)};
}

std::vector<double> depth_between_skin_and_inner_layer(const BodySurface& surface, std::span<const Vec3> points_mm) {
  const double bucket_mm = 2 * surface.cell_size_mm();
  const SampleLookup skin(surface.samples(SurfaceSide::outer), bucket_mm);
  const SampleLookup inner(surface.samples(SurfaceSide::inner), bucket_mm);
  std::vector<double> out;
  out.reserve(points_mm.size());
  for (const Vec3& p : points_mm) {
    const double d_skin = skin.distance(p);
    double d;
    if (!inner.empty()) {
      const double d_inner = inner.distance(p);
      d = d_skin + d_inner > 0 ? d_skin / (d_skin + d_inner) : 0;
    } else {
      const auto s = surface.project(p, std::numeric_limits<double>::infinity());
      const double thickness = s ? surface.thickness_mm(s->position_mm, -s->normal) : 0;
      d = thickness > 0 ? d_skin / thickness : 0;
    }
    out.push_back(std::clamp(d, 0.0, 1.0));
  }
  return out;
}

CutFaceColours colour_cut_faces(const BodySurface& surface, std::span<const CellFace> faces,
                                std::span<const Vec6> residual_stress_kPa) {
  const LinkedVolume& volume = surface.model().volume;
  const double h = volume.grid().cell_size_mm;
  CutFaceColours out;
  std::vector<Vec3> centres;
  for (const CellFace& f : faces) {
    const Vec3 n = face_step(f.face).cast<double>();
    centres.push_back(volume.cell_center_mm(f.cell) + 0.5 * h * n);
    const Vec6 s = residual_stress_kPa.empty() ? Vec6::Zero() : residual_stress_kPa[static_cast<std::size_t>(f.cell)];
    out.released_traction_kPa.push_back(released_traction_kPa(s, n));
  }
  out.depth = depth_between_skin_and_inner_layer(surface, centres);
  const auto [lo, hi] = std::minmax_element(out.released_traction_kPa.begin(), out.released_traction_kPa.end());
  for (std::size_t i = 0; i < faces.size(); ++i) {
    out.traction_rgb.push_back(red_blue(out.released_traction_kPa[i], *lo, *hi));
    const float t = static_cast<float>(out.depth[i]);
    out.depth_rgb.push_back({1.0f, t, 0.0f});
  }
  return out;
}

}  // namespace cleave
