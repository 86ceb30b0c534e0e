// Exact equilibration: T sigma = 0 at every vertex, the free uncut body does not move under it,
// and its volume-averaged stress is zero (Hoger's theorem), while the design alone moves it.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <cmath>
#include <limits>

#include "cleave/core/error.hpp"


#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/residual_stress_forces.hpp"
#include "cleave/fem/rigid_supports.hpp"
#include "cleave/stress/equilibrate_stress.hpp"
#include "cleave/stress/equilibrium_operator.hpp"
#include "cleave/stress/sparse_cholesky.hpp"
#include "cleave/stress/stress_designer.hpp"
#include "stress_test_models.hpp"

namespace cleave {
namespace {

/// Largest displacement (mm) of the body under residual stress: K u = -T sigma (full 2x2x2
/// stiffness, as the simulation) with `held` vertices at rest, or, when none are held, a 3-2-1
/// support (it carries no reaction for a self-balanced load).
double max_displacement_mm(const TissueModel& m, const std::vector<Vec6>& stress, const std::vector<VertexId>& held = {}) {
  SparseMatrix k = assemble_stiffness(m);
  Vector b = -residual_stress_forces(m.volume, stress);
  FixedDofs fixed = fix_vertices(m.volume.vertex_count(), held);
  if (held.empty()) add_rigid_supports(m.volume, fixed);
  eliminate_fixed_dofs(k, b, fixed);
  Eigen::SparseMatrix<double> k_col = k;
  k_col.makeCompressed();
  SparseCholesky cholesky;
  cholesky.factorize(k_col);
  const Vector u = cholesky.solve_refined(k_col, b);
  return u.cwiseAbs().maxCoeff();
}

/// Mean of n^T sigma n over the skin cells (label 1) for the frame's Langer and cross directions (kPa).
std::pair<double, double> skin_langer_cross_kPa(const TissueModel& m, const DesignResult& r, const std::vector<Vec6>& stress) {
  double langer = 0, cross = 0;
  int count = 0;
  for (CellId c = 0; c < m.volume.cell_count(); ++c) {
    if (m.volume.cell_label(c) != 1) continue;
    const DirectionFrame& f = r.frames[static_cast<std::size_t>(c)];
    const Mat3 s = from_voigt(stress[static_cast<std::size_t>(c)]);
    langer += f.langer.dot(s * f.langer);
    cross += f.cross.dot(s * f.cross);
    ++count;
  }
  return {langer / count, cross / count};
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
  // The designer takes both residuals from the equilibration's own forces: they equal the ones
  // measured with the matrix T (rounding aside, which is all of T sigma).
  const SparseMatrix t = stress_divergence_matrix(m.volume);
  const EquilibriumNorm norm = equilibrium_norm(t);
  EXPECT_NEAR(result.residual_designed, relative_equilibrium_residual(t, norm, result.designed_kPa), 1e-9 * result.residual_designed);
  EXPECT_NEAR(result.residual_final, relative_equilibrium_residual(t, norm, result.stress_kPa), 1e-13);

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

// Issue 4: the abdomen (a shell 2 to 4 cells thick, 5.7k cells) did not converge ("4.62e-07
// after 100 steps"): its bending and one-point hourglass modes are softer than the old shift.
// Both designs: the default (w_E = 0, control points reproduced; on the free shell this design is
// nearly compatible and relaxes almost completely, so the scale-free residual, relative to the small
// final ||sigma||, is a little larger) and the paper's eq. 6 penalty (w_E = 1).
class AbdomenEquilibration : public ::testing::TestWithParam<double> {};

TEST_P(AbdomenEquilibration, TheAbdomenDesignConvergesAndTheFreeBodyStaysAtRest) {
  const TissueModel m = test::builtin_model("abdomen");
  ASSERT_GT(m.volume.cell_count(), 5000);
  StressDesign d = test::abdomen_demo_design(m);
  d.weights.equilibrium = GetParam();
  d.equilibration = Equilibration::growth;
  const DesignResult result = design_residual_stress(m, d);

  // The equilibration stops at ||T sigma|| <= 5e-11 ||T sigma_d|| (its rounding floor lies between
  // 1e-12 and 5e-11). In the scale-free measure, relative to ||sigma||, that is up to ~6e-10 for
  // the default design (w_E = 0), which relaxes on the free shell to a sigma much smaller than
  // sigma_d: measured 4.8e-10 where CG stops just below the rule (4.1e-11 of the forces), 1.2e-11
  // where a double step overshot it; with w_E = 1, 6e-13 to 3.7e-12. The body's rest and Hoger's
  // mean are checked below.
  const double force_reduction = residual_stress_forces(m.volume, result.stress_kPa).norm() /
                                 residual_stress_forces(m.volume, result.designed_kPa).norm();
  EXPECT_LT(force_reduction, 5e-11);
  EXPECT_LT(result.residual_final, GetParam() == 0.0 ? 1e-9 : 1e-11);
  EXPECT_GT(result.residual_designed, 1e-2);
  const double size = m.size_mm();
  EXPECT_GT(max_displacement_mm(m, result.designed_kPa), 1e-3 * size);
  EXPECT_LT(max_displacement_mm(m, result.stress_kPa), 1e-6 * size);

  // Hoger: zero mean stress, relative to the largest designed stress.
  double largest = 0;
  for (const Vec6& s : result.designed_kPa) largest = std::max(largest, s.cwiseAbs().maxCoeff());
  Vec6 mean = Vec6::Zero();
  for (const Vec6& s : result.stress_kPa) mean += s;
  mean /= static_cast<double>(result.stress_kPa.size());
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 1e-9 * largest);
}

INSTANTIATE_TEST_SUITE_P(EquilibriumWeights, AbdomenEquilibration, ::testing::Values(0.0, 1.0));

// The demo holds the wall's rim. Equilibrium is imposed at the free vertices only (paper eq. 2
// holds on the free surface Gamma_N); the rim carries the reactions, as skin stretched over a
// frame, so the skin keeps a tension along Langer's lines well above the one across them. On the
// free body the same (uniform) design is compatible and relaxes completely.
TEST(Equilibration, WithTheRimHeldTheSkinKeepsItsLangerTension) {
  const TissueModel m = test::builtin_model("abdomen");
  StressDesign d = test::abdomen_demo_design(m);
  d.weights.equilibrium = 0;  // the plain Laplacian design: 20 / 10 kPa over the skin
  d.equilibration = Equilibration::growth;
  d.held_vertices = test::abdomen_rim_vertices(m);
  const DesignResult result = design_residual_stress(m, d);

  const auto [designed_langer, designed_cross] = skin_langer_cross_kPa(m, result, result.designed_kPa);
  EXPECT_NEAR(designed_langer, 20.0, 0.5);
  EXPECT_NEAR(designed_cross, 10.0, 0.5);
  const auto [langer, cross] = skin_langer_cross_kPa(m, result, result.stress_kPa);
  EXPECT_GT(langer, 2.0);            // measured 4.6 kPa
  EXPECT_GT(langer, 3.0 * cross);    // measured ratio 6

  // T sigma = 0 at every free vertex; the held body does not move under sigma.
  std::vector<std::uint8_t> held(static_cast<std::size_t>(m.volume.vertex_count()), 0);
  for (const VertexId v : d.held_vertices) held[static_cast<std::size_t>(v)] = 1;
  const Vector designed_forces = residual_stress_forces(m.volume, result.designed_kPa);
  const Vector forces = residual_stress_forces(m.volume, result.stress_kPa);
  double free_force = 0;
  for (VertexId v = 0; v < m.volume.vertex_count(); ++v)
    if (!held[static_cast<std::size_t>(v)]) free_force = std::max(free_force, forces.segment<3>(3 * v).cwiseAbs().maxCoeff());
  EXPECT_LT(free_force, 1e-9 * designed_forces.cwiseAbs().maxCoeff());
  EXPECT_LT(result.residual_final, 1e-11);  // measured 3.7e-12 (the stopping rule: 5e-11 of ||T sigma_d||)
  const double size = m.size_mm();
  EXPECT_GT(max_displacement_mm(m, result.designed_kPa, d.held_vertices), 1e-2 * size);
  EXPECT_LT(max_displacement_mm(m, result.stress_kPa, d.held_vertices), 1e-6 * size);
}

/// A tube's designed stress: Langer tension 20 kPa winding with z, turned further inside a
/// Gaussian spot around `spot_mm` (the kind of change a stroke edit makes), 10 kPa across.
std::vector<Vec6> spotted_design_kPa(const TissueModel& m, const Vec3& spot_mm) {
  std::vector<Vec6> out(static_cast<std::size_t>(m.volume.cell_count()));
  for (CellId c = 0; c < m.volume.cell_count(); ++c) {
    const Vec3 p = m.volume.cell_center_mm(c);
    const double angle = 0.05 * p.z() + 0.8 * std::exp(-0.02 * (p - spot_mm).squaredNorm());
    Vec6 s;
    s << 20.0 * std::cos(angle) * std::cos(angle), 20.0 * std::sin(angle) * std::sin(angle), 10.0,
        20.0 * std::sin(angle) * std::cos(angle), 0.0, 0.0;
    out[static_cast<std::size_t>(c)] = s;
  }
  return out;
}

// Edits: warm-started from the last solve, with the soft modes (what CG corrected after its first
// step) of the earlier ones. Each edit equals a fresh equilibration. A stroke dragged back and forth
// (or undone and redone) revisits designs: once one round taught the modes, each edit needs one solve
// with the factor; plain CG from the warm start needs two to four on this shell (measured).
TEST(Equilibration, EditsLearnTheSoftModesAndEqualAFreshEquilibration) {
  const TissueModel m = test::builtin_model("abdomen");
  const Vec3 c = m.volume.grid().origin_mm + 0.5 * m.volume.grid().extent_mm();
  const std::vector<Vec3> spots = {c + Vec3(-30.0, 5.0, 0.0), c + Vec3(0.0, -5.0, 3.0), c + Vec3(25.0, 0.0, -3.0)};
  std::vector<std::vector<Vec6>> designs, fresh;
  for (const Vec3& spot : spots) {
    designs.push_back(spotted_design_kPa(m, spot));
    fresh.push_back(equilibrate_stress(m, designs.back()).stress_kPa);
  }
  StressEquilibrator kept(m);
  (void)kept.equilibrate(spotted_design_kPa(m, c));
  int late_solves = 0;
  constexpr int kRounds = 3;
  for (int edit = 0; edit < kRounds * 3; ++edit) {
    const std::size_t which = static_cast<std::size_t>(edit % 3);
    const EquilibrationResult edited = kept.equilibrate(designs[which]);
    EXPECT_LE(edited.force_reduction, 1e-10);
    double difference = 0, largest = 0;
    for (std::size_t i = 0; i < edited.stress_kPa.size(); ++i) {
      difference = std::max(difference, (edited.stress_kPa[i] - fresh[which][i]).cwiseAbs().maxCoeff());
      largest = std::max(largest, fresh[which][i].cwiseAbs().maxCoeff());
    }
    EXPECT_LT(difference, 1e-8 * largest) << "edit " << edit;
    if (edit >= 3) late_solves += edited.refinement_steps;
  }
  // One edit may end a hair above the target and take a second solve (the rounding of the
  // substitution's schedule, which depends on the thread count); without the modes each takes 2-4.
  EXPECT_LE(late_solves, (kRounds - 1) * 3 + 1);
}

// Undo, redo and a stroke dragged back give a design equal to one of the last two, bit for bit:
// answered from memory with no solve, the same field as before; a new design after that starts
// from the recalled design's displacement and still equals a fresh equilibration.
TEST(Equilibration, TheLastTwoDesignsAreAnsweredWithoutASolve) {
  const TissueModel m = test::builtin_model("abdomen");
  const Vec3 c = m.volume.grid().origin_mm + 0.5 * m.volume.grid().extent_mm();
  const std::vector<Vec6> a = spotted_design_kPa(m, c + Vec3(-30.0, 5.0, 0.0));
  const std::vector<Vec6> b = spotted_design_kPa(m, c + Vec3(0.0, -5.0, 3.0));
  const std::vector<Vec6> third = spotted_design_kPa(m, c + Vec3(25.0, 0.0, -3.0));
  StressEquilibrator kept(m);
  const EquilibrationResult first_a = kept.equilibrate(a);
  const EquilibrationResult first_b = kept.equilibrate(b);
  ASSERT_GT(first_a.refinement_steps, 0);
  ASSERT_GT(first_b.refinement_steps, 0);
  for (int round = 0; round < 2; ++round) {
    const EquilibrationResult again_a = kept.equilibrate(a);
    EXPECT_EQ(again_a.refinement_steps, 0);
    EXPECT_TRUE(again_a.stress_kPa == first_a.stress_kPa);
    EXPECT_EQ(again_a.force_reduction, first_a.force_reduction);
    const EquilibrationResult again_b = kept.equilibrate(b);
    EXPECT_EQ(again_b.refinement_steps, 0);
    EXPECT_TRUE(again_b.stress_kPa == first_b.stress_kPa);
  }
  std::vector<Vec6> nudged = a;  // one cell's tensor one ulp off: a new design, solved
  nudged[0][0] = std::nextafter(nudged[0][0], 1e300);
  EXPECT_GT(kept.equilibrate(nudged).refinement_steps, 0);

  const EquilibrationResult edited = kept.equilibrate(third);
  const std::vector<Vec6> fresh = equilibrate_stress(m, third).stress_kPa;
  EXPECT_GT(edited.refinement_steps, 0);
  double difference = 0, largest = 0;
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    difference = std::max(difference, (edited.stress_kPa[i] - fresh[i]).cwiseAbs().maxCoeff());
    largest = std::max(largest, fresh[i].cwiseAbs().maxCoeff());
  }
  EXPECT_LT(difference, 1e-8 * largest);
}

// A picture first (EquilibrationPass::picture): an edit over fresh cells (no soft modes learned
// yet) whose first step ends between the target 5e-11 and 1e-6 returns that stress as
// provisional; finish() then takes the steps the complete pass takes, so the result, the
// iteration count and the soft modes learned are the complete pass's, bit for bit (the next edit
// agrees too). A newer edit drops a provisional result and still equals a fresh equilibration.
TEST(Equilibration, APictureFirstThenFinishIsTheCompletePassBitForBit) {
  const TissueModel m = test::builtin_model("abdomen");
  const Vec3 c = m.volume.grid().origin_mm + 0.5 * m.volume.grid().extent_mm();
  const std::vector<Vec6> start = spotted_design_kPa(m, c);
  const std::vector<Vec6> edit = spotted_design_kPa(m, c + Vec3(-30.0, 5.0, 0.0));
  const std::vector<Vec6> next = spotted_design_kPa(m, c + Vec3(25.0, 0.0, -3.0));
  StressEquilibrator complete(m), picture(m);
  (void)complete.equilibrate(start);
  (void)picture.equilibrate(start, EquilibrationPass::picture);  // may be provisional too
  if (picture.has_provisional()) (void)picture.finish();

  const EquilibrationResult whole = complete.equilibrate(edit);
  ASSERT_GT(whole.refinement_steps, 1) << "the edit must need more than its first step";
  const EquilibrationResult provisional = picture.equilibrate(edit, EquilibrationPass::picture);
  ASSERT_TRUE(provisional.provisional);
  EXPECT_TRUE(picture.has_provisional());
  EXPECT_EQ(provisional.refinement_steps, 1);
  EXPECT_GT(provisional.force_reduction, 5e-11);  // a complete pass would go on
  EXPECT_LE(provisional.force_reduction, kPictureReduction);
  EXPECT_EQ(provisional.designed_force_mN, whole.designed_force_mN);
  double difference = 0, largest = 0;
  for (std::size_t i = 0; i < whole.stress_kPa.size(); ++i) {
    difference = std::max(difference, (provisional.stress_kPa[i] - whole.stress_kPa[i]).cwiseAbs().maxCoeff());
    largest = std::max(largest, whole.stress_kPa[i].cwiseAbs().maxCoeff());
  }
  EXPECT_GT(difference, 0.0);
  EXPECT_LT(difference, 1e-4 * largest);  // what the picture cannot tell apart

  const EquilibrationResult finished = picture.finish();
  EXPECT_FALSE(finished.provisional);
  EXPECT_FALSE(picture.has_provisional());
  EXPECT_TRUE(finished.stress_kPa == whole.stress_kPa);
  EXPECT_EQ(finished.refinement_steps, whole.refinement_steps);
  EXPECT_EQ(finished.force_reduction, whole.force_reduction);
  try {
    (void)picture.finish();
    ADD_FAILURE() << "finish() without a provisional result must throw";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "stress equilibration: finish() without a provisional result; expected a call of equilibrate() "
                           "with EquilibrationPass::picture that returned one");
  }
  // The same soft modes and displacement: the next edit agrees bit for bit; the finished design
  // is remembered as the complete pass remembers it.
  const EquilibrationResult whole_next = complete.equilibrate(next);
  EXPECT_TRUE(picture.equilibrate(next).stress_kPa == whole_next.stress_kPa);
  EXPECT_EQ(picture.equilibrate(edit).refinement_steps, 0);

  // A provisional result dropped by a newer edit: that edit starts from the provisional
  // displacement and still equals a fresh equilibration.
  StressEquilibrator dropped(m);
  (void)dropped.equilibrate(start);
  ASSERT_TRUE(dropped.equilibrate(edit, EquilibrationPass::picture).provisional);
  const EquilibrationResult after = dropped.equilibrate(next);
  EXPECT_FALSE(dropped.has_provisional());
  EXPECT_LE(after.force_reduction, 1e-10);
  const std::vector<Vec6> fresh = equilibrate_stress(m, next).stress_kPa;
  difference = 0;
  largest = 0;
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    difference = std::max(difference, (after.stress_kPa[i] - fresh[i]).cwiseAbs().maxCoeff());
    largest = std::max(largest, fresh[i].cwiseAbs().maxCoeff());
  }
  EXPECT_LT(difference, 1e-8 * largest);
}

TEST(Equilibration, ABalancedFieldIsLeftAsItIs) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(8, 8, 2), std::nullopt});
  const std::vector<Vec6> zero(static_cast<std::size_t>(m.volume.cell_count()), Vec6::Zero());
  const EquilibrationResult r = equilibrate_stress(m, zero);
  EXPECT_EQ(r.refinement_steps, 0);
  for (const Vec6& s : r.stress_kPa) EXPECT_EQ(s, Vec6::Zero());
  std::vector<Vec6> bad = zero;
  bad[3][0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(equilibrate_stress(m, bad), InputError);
}

}  // namespace
}  // namespace cleave
