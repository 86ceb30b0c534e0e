// The direct least-squares ellipse fit recovers known ellipses.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "cleave/viz/ellipse_fit.hpp"

namespace cleave {
namespace {

std::vector<Eigen::Vector2d> ellipse_points(const Eigen::Vector2d& c, double a, double b, double angle, int n,
                                            double arc = 2 * std::numbers::pi) {
  std::vector<Eigen::Vector2d> p;
  const Eigen::Vector2d u(std::cos(angle), std::sin(angle)), v(-std::sin(angle), std::cos(angle));
  for (int k = 0; k < n; ++k) {
    const double t = arc * k / n;
    p.push_back(c + a * std::cos(t) * u + b * std::sin(t) * v);
  }
  return p;
}

TEST(FitEllipse, RecoversAxesOrientationAndCentre) {
  const double angle = 30.0 * std::numbers::pi / 180.0;
  const auto e = fit_ellipse(ellipse_points({3.0, -2.0}, 7.0, 4.0, angle, 40));
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->semi_major, 7.0, 1e-9);
  EXPECT_NEAR(e->semi_minor, 4.0, 1e-9);
  EXPECT_NEAR(e->angle_rad, angle, 1e-9);
  EXPECT_NEAR(e->centre.x(), 3.0, 1e-9);
  EXPECT_NEAR(e->centre.y(), -2.0, 1e-9);
  EXPECT_NEAR(e->axis_ratio(), 1.75, 1e-9);
}

TEST(FitEllipse, CircleHasRatioOneAndAngleIsFoldedIntoHalfTurn) {
  const auto c = fit_ellipse(ellipse_points({0, 0}, 5.0, 5.0, 0.0, 24));
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->axis_ratio(), 1.0, 1e-9);
  EXPECT_NEAR(c->semi_major, 5.0, 1e-9);
  const auto e = fit_ellipse(ellipse_points({0, 0}, 3.0, 1.0, 0.75 * std::numbers::pi, 30));  // 135 deg = -45 deg
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->angle_rad, -0.25 * std::numbers::pi, 1e-9);
}

TEST(FitEllipse, ArcOnlyStillFitsAndTooFewPointsDoNot) {
  const auto e = fit_ellipse(ellipse_points({1, 1}, 6.0, 2.0, 0.3, 30, std::numbers::pi));  // half the ellipse
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->semi_major, 6.0, 1e-7);
  EXPECT_NEAR(e->semi_minor, 2.0, 1e-7);
  EXPECT_FALSE(fit_ellipse(ellipse_points({0, 0}, 2.0, 1.0, 0.0, 4)));
  const std::vector<Eigen::Vector2d> line{{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}, {5, 5}};
  EXPECT_FALSE(fit_ellipse(line));
}

}  // namespace
}  // namespace cleave
