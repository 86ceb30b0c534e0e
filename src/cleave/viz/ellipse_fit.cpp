#include "cleave/viz/ellipse_fit.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>

namespace cleave {
namespace {

constexpr std::size_t kMinPoints = 5;

}  // namespace

Eigen::Vector2d Ellipse2::major_direction() const { return {std::cos(angle_rad), std::sin(angle_rad)}; }

std::optional<Ellipse2> fit_ellipse(std::span<const Eigen::Vector2d> points) {
  if (points.size() < kMinPoints) return std::nullopt;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  double rms = 0;
  for (const auto& p : points) rms += (p - mean).squaredNorm();
  rms = std::sqrt(rms / static_cast<double>(points.size()));
  if (!(rms > 0) || !std::isfinite(rms)) return std::nullopt;

  const Eigen::Index n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd d1(n, 3), d2(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d q = (points[static_cast<std::size_t>(i)] - mean) / rms;
    d1.row(i) << q.x() * q.x(), q.x() * q.y(), q.y() * q.y();
    d2.row(i) << q.x(), q.y(), 1.0;
  }
  const Eigen::Matrix3d s1 = d1.transpose() * d1;
  const Eigen::Matrix3d s2 = d1.transpose() * d2;
  const Eigen::Matrix3d s3 = d2.transpose() * d2;
  const Eigen::FullPivLU<Eigen::Matrix3d> s3_lu(s3);
  if (!s3_lu.isInvertible()) return std::nullopt;
  const Eigen::Matrix3d t = -s3_lu.solve(s2.transpose());
  const Eigen::Matrix3d m = s1 + s2 * t;
  Eigen::Matrix3d reduced;  // C1^-1 M with C1 the ellipse constraint 4ac - b^2 = 1
  reduced.row(0) = m.row(2) / 2;
  reduced.row(1) = -m.row(1);
  reduced.row(2) = m.row(0) / 2;
  const Eigen::EigenSolver<Eigen::Matrix3d> eig(reduced);
  std::optional<Eigen::Vector3d> a1;
  double best = 0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = eig.eigenvectors().col(k).real();
    const double constraint = 4 * v[0] * v[2] - v[1] * v[1];
    if (constraint > best) {
      best = constraint;
      a1 = v;
    }
  }
  if (!a1) return std::nullopt;
  const Eigen::Vector3d a2 = t * *a1;
  const double A = (*a1)[0], B = (*a1)[1], C = (*a1)[2], D = a2[0], E = a2[1], F = a2[2];
  Eigen::Matrix2d q;
  q << A, B / 2, B / 2, C;
  const Eigen::Vector2d centre = q.ldlt().solve(Eigen::Vector2d(-D / 2, -E / 2));
  const double f_centre = F + 0.5 * (D * centre.x() + E * centre.y());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> qe(q);
  const Eigen::Vector2d lambda = qe.eigenvalues();
  const double s_a = -f_centre / lambda[0];
  const double s_b = -f_centre / lambda[1];
  if (!(s_a > 0) || !(s_b > 0) || !std::isfinite(s_a) || !std::isfinite(s_b)) return std::nullopt;
  const double r0 = std::sqrt(s_a), r1 = std::sqrt(s_b);
  const int major = r0 >= r1 ? 0 : 1;
  const Eigen::Vector2d dir = qe.eigenvectors().col(major);
  Ellipse2 e;
  e.centre = mean + rms * centre;
  e.semi_major = rms * std::max(r0, r1);
  e.semi_minor = rms * std::min(r0, r1);
  double angle = std::atan2(dir.y(), dir.x());
  if (angle <= -std::numbers::pi / 2) angle += std::numbers::pi;
  if (angle > std::numbers::pi / 2) angle -= std::numbers::pi;
  e.angle_rad = angle;
  return e;
}

}  // namespace cleave
