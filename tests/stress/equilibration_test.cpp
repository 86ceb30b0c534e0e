// Exact equilibration: T sigma = 0 at every vertex, the free uncut body does not move under it,
// and its volume-averaged stress is zero (Hoger's theorem), while the design alone moves it.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"

#include <Eigen/SparseCholesky>

#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/residual_stress_forces.hpp"
#include "cleave/fem/rigid_supports.hpp"
#include "cleave/stress/equilibrate_stress.hpp"
#include "cleave/stress/stress_designer.hpp"
#include "stress_test_models.hpp"

namespace cleave {
namespace {

/// Largest displacement (mm) of the free body under residual stress: K u = -T sigma with a
/// 3-2-1 support (carries no reaction for a self-balanced load), Eigen's LDLT.
double max_displacement_mm(const TissueModel& m, const std::vector<Vec6>& stress) {
  SparseMatrix k = assemble_stiffness(m);
  Vector b = -residual_stress_forces(m.volume, stress);
  FixedDofs fixed = fix_vertices(m.volume.vertex_count(), {});
  add_rigid_supports(m.volume, fixed);
  eliminate_fixed_dofs(k, b, fixed);
  const Eigen::SparseMatrix<double> k_col = k;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k_col);
  const Vector u = ldlt.solve(b);
  return u.cwiseAbs().maxCoeff();
}

TEST(Equilibration, DesignedStressBecomesSelfBalancedAndTheBodyStaysAtRest) {
  const TissueModel m = test::builtin_model("cylinder", {Vec3i(14, 14, 10), std::nullopt});
  StressDesign d;
  const double z_mid = m.volume.grid().origin_mm.z() + 0.5 * m.volume.grid().extent_mm().z();
  d.strokes = {test::circumferential_stroke(m, z_mid)};
  const Vec3 c = test::tube_center(m);
  const double r = test::tube_outer_radius(m);
  d.control_points = {{{c.x() + r, c.y(), z_mid}, 20, 10}, {{c.x() - r, c.y(), z_mid}, 20, 10}};
  d.equilibration = Equilibration::growth;
  const DesignResult result = design_residual_stress(m, d);

  double largest_eigenvalue = 0;
  for (const Vec3& l : result.eigenvalues_kPa) largest_eigenvalue = std::max(largest_eigenvalue, l.cwiseAbs().maxCoeff());
  ASSERT_GT(largest_eigenvalue, 10.0);

  // T sigma = 0 at every vertex, relative to the forces of the design.
  const Vector designed_forces = residual_stress_forces(m.volume, result.designed_kPa);
  const Vector forces = residual_stress_forces(m.volume, result.stress_kPa);
  EXPECT_GT(designed_forces.cwiseAbs().maxCoeff(), 1.0);  // mN: the design alone is not balanced
  EXPECT_LT(forces.cwiseAbs().maxCoeff(), 1e-9 * designed_forces.cwiseAbs().maxCoeff());
  EXPECT_LT(result.residual_final, 1e-10);
  EXPECT_GT(result.residual_designed, 1e-4);

  // The free, uncut body does not move under its residual stress; under the raw design it does.
  const double size = m.size_mm();
  const double moved_design = max_displacement_mm(m, result.designed_kPa);
  const double moved = max_displacement_mm(m, result.stress_kPa);
  EXPECT_GT(moved_design, 1e-3 * size);
  EXPECT_LT(moved, 1e-6 * size);

  // Hoger: the volume average of a self-balanced stress is zero.
  Vec6 mean = Vec6::Zero();
  for (const Vec6& s : result.stress_kPa) mean += s;
  mean /= static_cast<double>(result.stress_kPa.size());
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 1e-6 * largest_eigenvalue);
}

TEST(Equilibration, ABalancedFieldIsLeftAsItIs) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(8, 8, 2), std::nullopt});
  const std::vector<Vec6> zero(static_cast<std::size_t>(m.volume.cell_count()), Vec6::Zero());
  const EquilibrationResult r = equilibrate_stress(m, zero);
  EXPECT_EQ(r.refinement_steps, 0);
  for (const Vec6& s : r.stress_kPa) EXPECT_EQ(s, Vec6::Zero());
  std::vector<Vec6> bad = zero;
  bad[3][0] = NAN;
  EXPECT_THROW(equilibrate_stress(m, bad), InputError);
}

}  // namespace
}  // namespace cleave
