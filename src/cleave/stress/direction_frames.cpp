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

}  // namespace

DirectionFrame direction_frame(const Mat3& langer_tensor, const Mat3& normal_tensor) {
  DirectionFrame frame;
  Eigen::SelfAdjointEigenSolver<Mat3> normal_eig;
  normal_eig.computeDirect(0.5 * (normal_tensor + normal_tensor.transpose()));
  Vec3 n = Vec3::UnitZ();
  if (normal_eig.eigenvalues()[2] > kNoDirection) {
    n = normal_eig.eigenvectors().col(2);
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

std::vector<DirectionFrame> direction_frames(const std::vector<Mat3>& langer_tensors, const std::vector<Mat3>& normal_tensors) {
  if (langer_tensors.size() != normal_tensors.size())
    throw InputError(fmt::format("direction frames got {} Langer and {} normal tensors; expected one of each per cell",
                                 langer_tensors.size(), normal_tensors.size()));
  std::vector<DirectionFrame> frames(langer_tensors.size());
  tbb::parallel_for(std::size_t{0}, frames.size(), [&](std::size_t c) { frames[c] = direction_frame(langer_tensors[c], normal_tensors[c]); });
  for (std::size_t c = 0; c < frames.size(); ++c)
    if (!frames[c].langer.allFinite() || !frames[c].cross.allFinite() || !frames[c].normal.allFinite())
      throw ComputeError(fmt::format("direction frames: the frame of cell {} is not finite; expected finite Langer and normal "
                                     "tensors",
                                     c));
  return frames;
}

double angle_between_lines_deg(const Vec3& d, const Vec3& e) {
  const double cosine = std::clamp(std::abs(d.normalized().dot(e.normalized())), 0.0, 1.0);
  return std::acos(cosine) * 180.0 / std::numbers::pi;
}

}  // namespace cleave
