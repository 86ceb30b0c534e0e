#include "cleave/stress/direction_frames.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
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

/// The frame about the normal axis `axis` (zero: none; the Langer tensor's weakest axis then).
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
  const Mat3 p = Mat3::Identity() - n * n.transpose();
  const Mat3 projected = p * langer_tensor * p;
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(0.5 * (projected + projected.transpose()));
  Vec3 t = eig.eigenvectors().col(2);
  t -= t.dot(n) * n;  // remove round-off along n
  if (eig.eigenvalues()[2] <= kNoDirection || t.norm() < 0.5) t = any_orthogonal(n);
  t.normalize();
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
