#pragma once
// Least-squares ellipse through 2D points: the direct (ellipse-specific) conic fit of Fitzgibbon,
// Pilu & Fisher (1999) in the numerically stable form of Halir & Flusser (1998), on points
// centred and scaled to unit RMS radius for conditioning.
//
//   std::optional<Ellipse2> e = fit_ellipse(points);   // nullopt: < 5 points or no ellipse
//   e->semi_major_mm, e->semi_minor_mm, e->angle_rad, e->axis_ratio()
#include <Eigen/Core>
#include <optional>
#include <span>

namespace cleave {

struct Ellipse2 {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double semi_major = 0;   ///< same unit as the points (mm)
  double semi_minor = 0;
  double angle_rad = 0;    ///< direction of the major axis from the first axis, in (-pi/2, pi/2]

  double axis_ratio() const { return semi_minor > 0 ? semi_major / semi_minor : 0; }
  Eigen::Vector2d major_direction() const;
};

std::optional<Ellipse2> fit_ellipse(std::span<const Eigen::Vector2d> points);

}  // namespace cleave
