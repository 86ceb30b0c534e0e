// Magnitudes to eigenvalues: control points reproduced, constants kept, equilibrium term works,
// the paper's CG and the default Cholesky agree, bad control points are refused.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"

#include <cmath>
#include <cstdio>

#include "cleave/stress/control_point_targets.hpp"
#include "cleave/stress/stress_designer.hpp"
#include "stress_test_models.hpp"

namespace cleave {
namespace {

StressDesign plate_design() {
  StressDesign d;
  d.strokes = {DesignStroke{{{10, 50, 10}, {90, 50, 10}}, StrokePlacement::surface}};
  d.control_points = {{{20, 20, 10}, 20, 10}, {{80, 80, 10}, 30, 5}, {{50, 50, 0}, 10, 10}};
  d.equilibration = Equilibration::none;
  return d;
}

TEST(EigenvalueField, ControlPointValuesAreReproducedWithinOnePercent) {
  const TissueModel m = test::builtin_model("plate");
  StressDesign d = plate_design();
  d.weights.equilibrium = 0;
  const DesignResult r = design_residual_stress(m, d);
  const auto targets = control_point_targets(m, d.control_points, 5.0);
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const Vec3& got = r.eigenvalues_kPa[static_cast<std::size_t>(targets[i].cell)];
    EXPECT_NEAR(got[0], d.control_points[i].langer_kPa, 0.01 * d.control_points[i].langer_kPa) << i;
    EXPECT_NEAR(got[1], d.control_points[i].cross_kPa, 0.01 * d.control_points[i].cross_kPa) << i;
    EXPECT_NEAR(got[2], 0.0, 0.01 * d.control_points[i].langer_kPa) << i;
  }
}

TEST(EigenvalueField, EqualControlValuesGiveAConstantField) {
  const TissueModel m = test::builtin_model("plate");
  StressDesign d = plate_design();
  d.weights.equilibrium = 0;
  for (DesignControlPoint& cp : d.control_points) {
    cp.langer_kPa = 20;
    cp.cross_kPa = 10;
  }
  const DesignResult r = design_residual_stress(m, d);
  double worst = 0;
  for (const Vec3& l : r.eigenvalues_kPa) worst = std::max(worst, (l - Vec3(20, 10, 0)).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-6 * 20);
}

/// The default solver and the paper's CG on the coupled 3 n_c system agree, with the eq. 6 rows
/// (w_E = 1, coupled Cholesky) and without them (w_E = 0: three independent scalar fields).
class EigenvalueSolvers : public ::testing::TestWithParam<double> {};

TEST_P(EigenvalueSolvers, PaperCgAndDefaultCholeskyAgree) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(16, 16, 2), std::nullopt});
  StressDesign d = plate_design();
  d.weights.equilibrium = GetParam();
  const DesignResult cholesky = design_residual_stress(m, d);
  d.solver = EigenvalueSolver::paper_cg;
  const DesignResult cg = design_residual_stress(m, d);
  EXPECT_GT(cg.eigenvalue_iterations, 0);
  double difference = 0, size = 0;
  for (std::size_t c = 0; c < cg.eigenvalues_kPa.size(); ++c) {
    difference = std::max(difference, (cg.eigenvalues_kPa[c] - cholesky.eigenvalues_kPa[c]).cwiseAbs().maxCoeff());
    size = std::max(size, cholesky.eigenvalues_kPa[c].cwiseAbs().maxCoeff());
  }
  EXPECT_LT(difference, 1e-4 * size);
}

INSTANTIATE_TEST_SUITE_P(EquilibriumWeights, EigenvalueSolvers, ::testing::Values(1.0, 0.0));

TEST(EigenvalueField, EquilibriumTermReducesTheResidualTenfoldOnTheAbdomen) {
  const TissueModel m = test::builtin_model("abdomen");
  const GridSpec& g = m.volume.grid();
  const Vec3 lo = g.origin_mm, ext = g.extent_mm();
  StressDesign d;
  d.equilibration = Equilibration::none;
  // A stroke across the dome top (x direction) and three control points on the skin.
  const auto top_of = [&](double fx, double fz) {
    const Vec3 p(lo.x() + fx * ext.x(), lo.y() + ext.y(), lo.z() + fz * ext.z());
    for (double y = p.y(); y > lo.y(); y -= 0.25 * g.cell_size_mm)
      if (m.volume.cell_containing({p.x(), y, p.z()}) != kNone) return Vec3(p.x(), y, p.z());
    return p;
  };
  d.strokes = {DesignStroke{{top_of(0.3, 0.5), top_of(0.5, 0.5), top_of(0.7, 0.5)}, StrokePlacement::surface}};
  d.control_points = {{top_of(0.3, 0.3), 20, 10}, {top_of(0.5, 0.5), 20, 10}, {top_of(0.7, 0.7), 20, 10}};
  d.weights.equilibrium = 0;
  const DesignResult without = design_residual_stress(m, d);
  d.weights.equilibrium = 1e5;  // the equilibrium rows must outweigh the smoothness on a staircase surface
  const DesignResult with = design_residual_stress(m, d);

  RecordProperty("residual_without", std::to_string(without.residual_designed));
  RecordProperty("residual_with", std::to_string(with.residual_designed));
  EXPECT_GT(without.residual_designed, 0.0);
  EXPECT_LT(with.residual_designed * 10.0, without.residual_designed)
      << "without " << without.residual_designed << " with " << with.residual_designed;
}

TEST(EigenvalueField, BadControlPointsAreRefused) {
  const TissueModel m = test::builtin_model("plate");
  const auto message = [&](const std::vector<DesignControlPoint>& cps) {
    try {
      control_point_targets(m, cps, 5.0);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({}),
            "design control points: the design has none; expected at least one control point with the Langer and cross "
            "eigenvalues (kPa), without which the stress would silently be zero");
  EXPECT_EQ(message({{{50, 50, 40}, 20, 10}}),
            "design control point 0 at (50, 50, 40) mm is 30.1 mm from the body surface; expected within 5 mm");
  EXPECT_EQ(message({{{50, 50, 10}, std::numeric_limits<double>::quiet_NaN(), 10}}),
            "design control point 0 eigenvalues (nan, 10) are not finite; expected stresses in kPa");
  EXPECT_EQ(message({{{50, std::numeric_limits<double>::infinity(), 10}, 20, 10}}), "design control point 0 position is not finite; expected coordinates in mm");
}

}  // namespace
}  // namespace cleave
