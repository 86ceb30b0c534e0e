// Langer's experiment on a thin plate: a round hole cut into a plate under uniform biaxial
// residual stress (p along x, q along y) opens into an ellipse. Plane-stress analytic solution
// (Kirsch's hole minus the uniform field) at the hole edge r = a:
//   Delta u_r(theta) = a / (2E) [ (p + q)(1 + nu) + (p - q)(3 - nu) cos 2 theta ].
// The FE model: one cell thick plate (free top and bottom faces), 16 a wide, cells a/5, the
// analytic displacement prescribed on the outer edge; the plug inside the circle is cut free and
// must not break the solve.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <numbers>

#include "cleave/fem/solve_static.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

constexpr int kCellsPerRadius = 5;      // cells no larger than a / 5
constexpr int kPlateRadii = 16;         // plate width in hole radii
constexpr double kCell_mm = 1.0;
constexpr double kRadius_mm = kCellsPerRadius * kCell_mm;
constexpr double kE_kPa = 80.0;
constexpr double kNu = 0.4;

/// Displacement released by the hole at r >= a (centre at the origin), plane stress.
Vec3 analytic_release_mm(const Vec3& x, double p, double q) {
  const double r = std::hypot(x.x(), x.y());
  const double t = std::atan2(x.y(), x.x());
  const double a = kRadius_mm;
  const double a2 = a * a / r;
  const double a4 = a * a * a * a / (r * r * r);
  const double s = (p - q) / 2.0;
  const double ur = (p + q) / 2.0 * (1 + kNu) * a2 / kE_kPa + s / kE_kPa * (4 * a2 - (1 + kNu) * a4) * std::cos(2 * t);
  const double ut = s / kE_kPa * (-2 * (1 - kNu) * a2 - (1 + kNu) * a4) * std::sin(2 * t);
  return {ur * std::cos(t) - ut * std::sin(t), ur * std::sin(t) + ut * std::cos(t), 0.0};
}

struct HoleFit {
  double mean_mm;  ///< Delta u_r averaged over the hole edge
  double cos2_mm;  ///< coefficient of cos 2 theta
  double sin2_mm;  ///< coefficient of sin 2 theta (0 by symmetry)
};

HoleFit release_hole(double p_kPa, double q_kPa) {
  const int n = kCellsPerRadius * kPlateRadii;
  TissueModel model = test::make_box_model({n, n, 1}, kCell_mm, kE_kPa, kNu);
  const Vec3 centre{n / 2 * kCell_mm, n / 2 * kCell_mm, 0.0};
  LinkedVolume& volume = model.volume;
  const auto in_plug = [&](CellId c) {
    const Vec3 d = volume.cell_center_mm(c) - centre;
    return std::hypot(d.x(), d.y()) < kRadius_mm;
  };
  volume.cut_links(test::faces_between(volume, in_plug));
  EXPECT_EQ(volume.component_count(), 2);

  Vec6 stress;
  stress << p_kPa, q_kPa, 0, 0, 0, 0;
  const std::vector<Vec6> field(static_cast<std::size_t>(volume.cell_count()), stress);
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.settings.relative_tolerance = 1e-10;
  const double outer = n / 2 * kCell_mm - 1e-9;
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const Vec3 d = volume.vertex_position_mm(v) - centre;
    if (std::abs(d.x()) >= outer || std::abs(d.y()) >= outer) {
      options.fixed_vertices.push_back(v);
      options.fixed_displacement_mm.push_back(analytic_release_mm(d, p_kPa, q_kPa));
    }
  }
  const StaticResult r = solve_static(model, field, options);
  EXPECT_EQ(r.free_components, 1);  // the plug

  // Hole edge: the vertices of the plate cells on the cut faces; fit c0 + c2 cos 2t + s2 sin 2t.
  std::vector<std::uint8_t> edge(static_cast<std::size_t>(volume.vertex_count()), 0);
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    if (in_plug(c)) continue;
    for (Face f = 0; f < kFaceCount; ++f)
      if (volume.neighbor(c, f) != kNone && volume.is_cut(c, f))
        for (const int corner : face_corners(f)) edge[static_cast<std::size_t>(volume.corner_vertex(c, corner))] = 1;
  }
  std::vector<std::array<double, 4>> rows;  // 1, cos 2t, sin 2t, u_r
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    if (!edge[static_cast<std::size_t>(v)]) continue;
    const Vec3 d = volume.vertex_position_mm(v) - centre;
    const double t = std::atan2(d.y(), d.x());
    const Vec3 u = r.displacement_mm[static_cast<std::size_t>(v)];
    rows.push_back({1.0, std::cos(2 * t), std::sin(2 * t), (u.x() * d.x() + u.y() * d.y()) / std::hypot(d.x(), d.y())});
  }
  Eigen::MatrixXd a(static_cast<Eigen::Index>(rows.size()), 3);
  Eigen::VectorXd b(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (int j = 0; j < 3; ++j) a(static_cast<Eigen::Index>(i), j) = rows[i][static_cast<std::size_t>(j)];
    b[static_cast<Eigen::Index>(i)] = rows[i][3];
  }
  const Eigen::Vector3d coefficients = a.colPivHouseholderQr().solve(b);
  return {coefficients[0], coefficients[1], coefficients[2]};
}

TEST(HoleRelease, AnisotropicStressOpensAnEllipseAlongTheLargerStress) {
  const double p = 20.0, q = 10.0;  // kPa, the paper's Langer / cross-Langer tensions
  const HoleFit fit = release_hole(p, q);
  const double mean = kRadius_mm / (2 * kE_kPa) * (p + q) * (1 + kNu);
  const double cos2 = kRadius_mm / (2 * kE_kPa) * (p - q) * (3 - kNu);
  std::printf("hole p=%g q=%g: mean %.4f mm (analytic %.4f), cos2 %.4f mm (analytic %.4f), sin2 %.2e\n", p, q, fit.mean_mm,
              mean, fit.cos2_mm, cos2, fit.sin2_mm);
  EXPECT_NEAR(fit.mean_mm, mean, 0.10 * mean);
  EXPECT_NEAR(fit.cos2_mm, cos2, 0.10 * cos2);
  EXPECT_GT(fit.cos2_mm, 0.0);  // long axis along x, the larger stress
  EXPECT_LT(std::abs(fit.sin2_mm), 1e-6 * mean);
}

TEST(HoleRelease, EqualBiaxialStressOpensACircle) {
  const double p = 15.0;
  const HoleFit fit = release_hole(p, p);
  const double mean = kRadius_mm * (1 + kNu) * p / kE_kPa;
  std::printf("hole p=q=%g: mean %.4f mm (analytic %.4f), cos2 %.2e, sin2 %.2e\n", p, fit.mean_mm, mean, fit.cos2_mm, fit.sin2_mm);
  EXPECT_NEAR(fit.mean_mm, mean, 0.10 * mean);
  EXPECT_LT(std::abs(fit.cos2_mm), 1e-6 * mean);
  EXPECT_LT(std::abs(fit.sin2_mm), 1e-6 * mean);
}

}  // namespace
}  // namespace cleave
