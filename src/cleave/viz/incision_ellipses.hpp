#pragma once
// Measuring an opened round incision the way Langer read his cadavers (paper section 5, fig. 7):
// the outer wound margin (the rim where the incision meets the skin) and the inner margin (the
// rim at the incision's depth) are sampled on the ideal circle of the reference configuration,
// moved by the displacement of the body side of the wall (not the plug), projected onto the
// incision's tangent plane (u, v) and fitted with ellipses (ellipse_fit.hpp). Sampling the ideal
// circle keeps the voxel staircase of the wall out of the fit: an undeformed incision measures as
// a circle of the requested radius exactly.
//
//   IncisionMeasurement m = *measure_incision(surface, displacement_mm, frame, reference);
//   m.outer.axis_ratio(), m.outer.semi_major, m.gap_mm, m.langer_angle_deg
//
// The samples (where each sits on the reference body, in which body-side cell) do not depend on
// the displacement: sample them once per cut body and measure every later displacement with them
// (the studio measures its 53 preview incisions after every edit):
//   IncisionMargins margins = sample_incision_margins(surface, frame);
//   m = *measure_incision(volume, margins, displacement_mm, frame, reference);
//
// The reference direction is the designed Langer direction at the incision, or, without a
// design, the major principal direction of the residual stress in the tangent plane
// (principal_tangent_direction). Returns nullopt when the margins cannot be sampled (no body
// cell next to the wall) or no ellipse fits.
#include <optional>
#include <span>
#include <vector>

#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/round_incision_links.hpp"
#include "cleave/viz/displacement_at_point.hpp"
#include "cleave/viz/ellipse_fit.hpp"

namespace cleave {

/// A direction in the tangent plane with the ratio of the larger to the smaller in-plane
/// eigenvalue there (infinity when the smaller is <= 0).
struct TangentDirection {
  Vec3 direction = Vec3::UnitX();
  double eigenvalue_ratio = 1;
};

/// Major eigenvector of the stress projected onto the plane with unit normal `normal`.
TangentDirection principal_tangent_direction(const Vec6& stress_kPa, const Vec3& normal);

struct IncisionMeasurement {
  Ellipse2 outer;             ///< outer margin in (u, v) coordinates of the frame, mm
  Ellipse2 inner;             ///< inner margin, mm
  Vec3 outer_major = Vec3::UnitX();  ///< unit direction of the outer long axis in space
  double gap_mm = 0;          ///< mean outer radius minus mean inner radius
  double opening_mm = 0;      ///< mean outer radius minus the incision's radius
  std::optional<double> langer_angle_deg;  ///< between outer long axis and reference, in [0, 90]
  std::optional<double> reference_eigenvalue_ratio;
};

/// Number of points sampled on each margin.
inline constexpr int kMarginSamples = 72;

/// One margin sample: its position on the reference body (the ideal circle, the outer one snapped
/// to the skin) and where it sits in the body-side cell whose displacement moves it.
struct MarginSample {
  Vec3 position_mm = Vec3::Zero();
  CellPoint at;
};

/// The samples of an incision's outer and inner margin (those with a body-side cell next to them).
struct IncisionMargins {
  std::vector<MarginSample> outer, inner;
};

IncisionMargins sample_incision_margins(const BodySurface& surface, const IncisionFrame& frame);

/// Samples the margins on `surface` and measures them under `displacement_mm`.
std::optional<IncisionMeasurement> measure_incision(const BodySurface& surface, std::span<const Vec3> displacement_mm,
                                                    const IncisionFrame& frame,
                                                    const std::optional<TangentDirection>& reference);

/// Measures margins sampled before on the same body (`volume`: its cells and vertices).
std::optional<IncisionMeasurement> measure_incision(const LinkedVolume& volume, const IncisionMargins& margins,
                                                    std::span<const Vec3> displacement_mm, const IncisionFrame& frame,
                                                    const std::optional<TangentDirection>& reference);

/// Angle (degrees, in [0, 90]) between two undirected lines.
double line_angle_deg(const Vec3& a, const Vec3& b);

}  // namespace cleave
