#include "cleave/viz/incision_ellipses.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "cleave/viz/displacement_at_point.hpp"

namespace cleave {
namespace {

constexpr double kSkinSnapCells = 1.5;  ///< rim points are snapped to the skin within this distance

enum class Margin { outer_at_skin, inner_at_depth };

std::vector<MarginSample> sample_margin(const BodySurface& surface, const IncisionFrame& frame, Margin margin) {
  const double at_depth_mm = margin == Margin::outer_at_skin ? 0.0 : frame.depth_mm;
  const LinkedVolume& volume = surface.model().volume;
  const auto body_side = [&](CellId c) { return frame.radial_of(volume.cell_center_mm(c)) > frame.radius_mm; };
  std::vector<MarginSample> samples;
  for (int k = 0; k < kMarginSamples; ++k) {
    Vec3 x = frame.rim_point(2 * std::numbers::pi * k / kMarginSamples, at_depth_mm);
    if (margin == Margin::outer_at_skin)
      if (const auto s = surface.project(x, kSkinSnapCells * surface.cell_size_mm())) x = s->position_mm;
    if (const std::optional<CellPoint> at = locate_in_accepted_cell(volume, x, body_side)) samples.push_back({x, *at});
  }
  return samples;
}

std::optional<Ellipse2> fit_margin(const LinkedVolume& volume, const std::vector<MarginSample>& samples,
                                   std::span<const Vec3> displacement_mm, const IncisionFrame& frame) {
  if (samples.size() < static_cast<std::size_t>(kMarginSamples / 2)) return std::nullopt;
  std::vector<Eigen::Vector2d> points;
  points.reserve(samples.size());
  for (const MarginSample& sample : samples) {
    const Vec3 d = sample.position_mm + displacement_at(volume, displacement_mm, sample.at) - frame.centre_mm;
    points.emplace_back(d.dot(frame.tangent_u), d.dot(frame.tangent_v));
  }
  return fit_ellipse(points);
}

}  // namespace

TangentDirection principal_tangent_direction(const Vec6& stress_kPa, const Vec3& normal) {
  const auto [u, v] = tangent_frame(normal);
  const Mat3 s = from_voigt(stress_kPa);
  Eigen::Matrix2d p;
  p << u.dot(s * u), u.dot(s * v), v.dot(s * u), v.dot(s * v);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(p);
  const Eigen::Vector2d major = eig.eigenvectors().col(1);
  TangentDirection out;
  out.direction = (major.x() * u + major.y() * v).normalized();
  const double lo = eig.eigenvalues()[0], hi = eig.eigenvalues()[1];
  out.eigenvalue_ratio = lo > 0 ? hi / lo : std::numeric_limits<double>::infinity();
  return out;
}

double line_angle_deg(const Vec3& a, const Vec3& b) {
  const double c = std::abs(a.normalized().dot(b.normalized()));
  return std::acos(std::min(1.0, c)) * 180.0 / std::numbers::pi;
}

IncisionMargins sample_incision_margins(const BodySurface& surface, const IncisionFrame& frame) {
  return {sample_margin(surface, frame, Margin::outer_at_skin), sample_margin(surface, frame, Margin::inner_at_depth)};
}

std::optional<IncisionMeasurement> measure_incision(const BodySurface& surface, std::span<const Vec3> displacement_mm,
                                                    const IncisionFrame& frame,
                                                    const std::optional<TangentDirection>& reference) {
  return measure_incision(surface.model().volume, sample_incision_margins(surface, frame), displacement_mm, frame, reference);
}

std::optional<IncisionMeasurement> measure_incision(const LinkedVolume& volume, const IncisionMargins& margins,
                                                    std::span<const Vec3> displacement_mm, const IncisionFrame& frame,
                                                    const std::optional<TangentDirection>& reference) {
  const auto outer = fit_margin(volume, margins.outer, displacement_mm, frame);
  const auto inner = fit_margin(volume, margins.inner, displacement_mm, frame);
  if (!outer || !inner) return std::nullopt;
  IncisionMeasurement m;
  m.outer = *outer;
  m.inner = *inner;
  const Eigen::Vector2d d = outer->major_direction();
  m.outer_major = (d.x() * frame.tangent_u + d.y() * frame.tangent_v).normalized();
  const double outer_mean = 0.5 * (outer->semi_major + outer->semi_minor);
  const double inner_mean = 0.5 * (inner->semi_major + inner->semi_minor);
  m.gap_mm = outer_mean - inner_mean;
  m.opening_mm = outer_mean - frame.radius_mm;
  if (reference) {
    const Vec3 in_plane = reference->direction - reference->direction.dot(frame.normal) * frame.normal;
    if (in_plane.norm() > 0) m.langer_angle_deg = line_angle_deg(m.outer_major, in_plane);
    m.reference_eigenvalue_ratio = reference->eigenvalue_ratio;
  }
  return m;
}

}  // namespace cleave
