#include "cleave/stress/direction_frames.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <numbers>

#include <tbb/parallel_for.h>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

/// A line tensor whose largest eigenvalue is below this (trace-1 units) carries no direction.
constexpr double kNoDirection = 1e-12;

/// Unit vector orthogonal to n, the coordinate axis most orthogonal to n projected.
Vec3 any_orthogonal(const Vec3& n) {
  Vec3 axis = Vec3::UnitX();
  if (std::abs(n.x()) > std::abs(n.y()) && std::abs(n.x()) > std::abs(n.z())) axis = Vec3::UnitY();
  const Vec3 t = axis - axis.dot(n) * n;
  return t.normalized();
}

/// The principal eigenvector of a normal tensor, zero when it carries no direction.
Vec3 normal_axis(const Mat3& normal_tensor) {
  Eigen::SelfAdjointEigenSolver<Mat3> normal_eig;
  normal_eig.computeDirect(0.5 * (normal_tensor + normal_tensor.transpose()));
  return normal_eig.eigenvalues()[2] > kNoDirection ? Vec3(normal_eig.eigenvectors().col(2)) : Vec3::Zero();
}

/// The principal axis of the symmetric 2x2 matrix [a b; b c] in the basis (e1, e2), as a unit
/// vector; zero when its larger eigenvalue is at most kNoDirection or the two eigenvalues are
/// equal (no preferred axis). Of the two forms of the eigenvector, (b, l - a) and (l - c, b), the
/// longer one: the other vanishes where the axis is (near) e1 or e2. NaN for a non-finite matrix,
/// so that the frame is refused (check_frames_finite) rather than given an arbitrary axis.
Vec3 principal_axis_in_plane(double a, double b, double c, const Vec3& e1, const Vec3& e2) {
  if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c)) return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  const double half_gap = 0.5 * (a - c);
  const double radius = std::hypot(half_gap, b);
  const double largest = 0.5 * (a + c) + radius;
  if (!(largest > kNoDirection) || !(radius > 0.0)) return Vec3::Zero();
  const double along_e1 = half_gap >= 0.0 ? half_gap + radius : b;  // l - c or b
  const double along_e2 = half_gap >= 0.0 ? b : radius - half_gap;  // b or l - a
  return (along_e1 * e1 + along_e2 * e2).normalized();
}

/// The frame about the normal axis `axis` (zero: none; the Langer tensor's weakest axis then).
/// The Langer direction is the principal axis of the Langer tensor projected onto the plane
/// normal to n, found as a 2x2 problem in that plane (the 3x3 eigen-solve of P L P it replaces
/// gave the same axis, at twice the time per cell).
DirectionFrame frame_about(const Mat3& langer_tensor, const Vec3& axis) {
  DirectionFrame frame;
  Vec3 n = Vec3::UnitZ();
  if (axis != Vec3::Zero()) {
    n = axis;
  } else {
    Eigen::SelfAdjointEigenSolver<Mat3> langer_eig;
    langer_eig.computeDirect(0.5 * (langer_tensor + langer_tensor.transpose()));
    if (langer_eig.eigenvalues()[2] > kNoDirection) n = langer_eig.eigenvectors().col(0);
  }
  n.normalize();
  const Vec3 e1 = any_orthogonal(n);
  const Vec3 e2 = n.cross(e1);
  const Mat3 symmetric = 0.5 * (langer_tensor + langer_tensor.transpose());
  const Vec3 l_e1 = symmetric * e1;
  Vec3 t = principal_axis_in_plane(e1.dot(l_e1), e2.dot(l_e1), e2.dot(symmetric * e2), e1, e2);
  if (t == Vec3::Zero()) t = e1;
  frame.normal = n;
  frame.langer = t;
  frame.cross = n.cross(t).normalized();
  return frame;
}

void check_frames_finite(const std::vector<DirectionFrame>& frames) {
  for (std::size_t c = 0; c < frames.size(); ++c)
    if (!frames[c].langer.allFinite() || !frames[c].cross.allFinite() || !frames[c].normal.allFinite())
      throw ComputeError(fmt::format("direction frames: the frame of cell {} is not finite; expected finite Langer and normal "
                                     "tensors",
                                     c));
}

void check_one_per_cell(std::size_t langer, std::size_t normal, const char* what) {
  if (langer != normal)
    throw InputError(
        fmt::format("direction frames got {} Langer tensors and {} normal {}; expected one of each per cell", langer, normal, what));
}

}  // namespace

DirectionFrame direction_frame(const Mat3& langer_tensor, const Mat3& normal_tensor) {
  return frame_about(langer_tensor, normal_axis(normal_tensor));
}

std::vector<Vec3> normal_axes(const std::vector<Mat3>& normal_tensors) {
  std::vector<Vec3> axes(normal_tensors.size());
  tbb::parallel_for(std::size_t{0}, axes.size(), [&](std::size_t c) { axes[c] = normal_axis(normal_tensors[c]); });
  return axes;
}

std::vector<DirectionFrame> direction_frames(const std::vector<Mat3>& langer_tensors, const std::vector<Mat3>& normal_tensors) {
  check_one_per_cell(langer_tensors.size(), normal_tensors.size(), "tensors");
  std::vector<DirectionFrame> frames(langer_tensors.size());
  tbb::parallel_for(std::size_t{0}, frames.size(), [&](std::size_t c) { frames[c] = direction_frame(langer_tensors[c], normal_tensors[c]); });
  check_frames_finite(frames);
  return frames;
}

std::vector<DirectionFrame> direction_frames(const std::vector<Mat3>& langer_tensors, const std::vector<Vec3>& normal_axes) {
  check_one_per_cell(langer_tensors.size(), normal_axes.size(), "axes");
  std::vector<DirectionFrame> frames(langer_tensors.size());
  tbb::parallel_for(std::size_t{0}, frames.size(), [&](std::size_t c) { frames[c] = frame_about(langer_tensors[c], normal_axes[c]); });
  check_frames_finite(frames);
  return frames;
}

double angle_between_lines_deg(const Vec3& d, const Vec3& e) {
  const double cosine = std::clamp(std::abs(d.normalized().dot(e.normalized())), 0.0, 1.0);
  return std::acos(cosine) * 180.0 / std::numbers::pi;
}

}  // namespace cleave
