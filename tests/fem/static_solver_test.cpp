// StaticSolver: one assembly, support choice and factorisation for many residual stresses (the
// studio's incision preview after a design edit). Each solve must equal a fresh solve_static.
#include <gtest/gtest.h>

#include <thread>

#include "cleave/core/error.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/solve_static.hpp"
#include "cleave/fem/static_solver.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

double max_difference_mm(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double worst = 0;
  for (std::size_t v = 0; v < a.size(); ++v) worst = std::max(worst, (a[v] - b[v]).norm());
  return worst;
}

double max_norm_mm(const std::vector<Vec3>& a) {
  double worst = 0;
  for (const Vec3& u : a) worst = std::max(worst, u.norm());
  return worst;
}

/// A stress varying from cell to cell (kPa): sigma_xx grows along x, sigma_yz along z.
std::vector<Vec6> graded_stress(const LinkedVolume& volume, double scale_kPa) {
  std::vector<Vec6> stress(static_cast<std::size_t>(volume.cell_count()), Vec6::Zero());
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Vec3i at = volume.cell_voxel(c);
    stress[static_cast<std::size_t>(c)] << scale_kPa * (1 + at.x()), 0.5 * scale_kPa, 0, 0, 0, 0.2 * scale_kPa * at.z();
  }
  return stress;
}

TEST(StaticSolver, RepeatedSolvesEqualFreshSolvesOnACutBodyWithPrescribedSupports) {
  TissueModel model = test::make_box_model({8, 4, 3}, 2.0);
  // cut the box in two at x = 8 mm: the held half and a free piece (3-2-1 supported)
  (void)model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) { return model.volume.cell_voxel(c).x() < 4; }));
  ASSERT_EQ(model.volume.component_count(), 2);
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.fixed_vertices = vertices_in_box(model.volume, Vec3(-0.1, -1, -1), Vec3(0.1, 9, 7));
  ASSERT_FALSE(options.fixed_vertices.empty());
  options.fixed_displacement_mm.assign(options.fixed_vertices.size(), Vec3(0.01, -0.02, 0.005));

  StaticSolver statics(model, options);
  EXPECT_FALSE(statics.set_up());
  for (const double scale_kPa : {20.0, -7.0, 3.5}) {
    SCOPED_TRACE(scale_kPa);
    const std::vector<Vec6> stress = graded_stress(model.volume, scale_kPa);
    const StaticResult kept = statics.solve(stress);
    const StaticResult fresh = solve_static(model, stress, options);
    ASSERT_GT(max_norm_mm(fresh.displacement_mm), 1e-3);
    EXPECT_LT(max_difference_mm(kept.displacement_mm, fresh.displacement_mm), 1e-10 * max_norm_mm(fresh.displacement_mm));
    EXPECT_EQ(kept.free_components, 1);
  }
  EXPECT_TRUE(statics.set_up());
  EXPECT_EQ(statics.solves(), 3);
}

/// CHOLMOD statics of a 6 x 3 x 3 box of 2 mm cells held at x = 0.
StaticOptions held_at_left_end(const TissueModel& model) {
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.fixed_vertices = vertices_in_box(model.volume, Vec3(-0.1, -1, -1), Vec3(0.1, 7, 7));
  return options;
}

TEST(StaticSolver, SetUpOnAnotherThreadThenSolvedHereEqualsAFreshSolve) {
  // The studio factors a new cut model on a thread of its own and solves with it on its worker.
  const TissueModel model = test::make_box_model({6, 3, 3}, 2.0);
  const StaticOptions options = held_at_left_end(model);
  StaticSolver statics(model, options);
  std::thread([&] { statics.set_up_solver(); }).join();
  EXPECT_TRUE(statics.set_up());
  EXPECT_EQ(statics.solves(), 0) << "set up, not solved";
  statics.set_up_solver();  // set up already: nothing happens
  const std::vector<Vec6> stress = graded_stress(model.volume, 10.0);
  const StaticResult kept = statics.solve(stress);
  const StaticResult fresh = solve_static(model, stress, options);
  ASSERT_GT(max_norm_mm(fresh.displacement_mm), 1e-3);
  EXPECT_LT(max_difference_mm(kept.displacement_mm, fresh.displacement_mm), 1e-10 * max_norm_mm(fresh.displacement_mm));
  EXPECT_EQ(statics.solves(), 1);
}

// Undo, redo and a drag back in the studio solve the preview again with a stress equal to one of
// the last two: answered from memory, equal to the first solve, with no solve; a third stress
// pushes the oldest out.
TEST(StaticSolver, TheLastTwoStressesAreAnsweredWithoutASolve) {
  const TissueModel model = test::make_box_model({6, 3, 3}, 2.0);
  const StaticOptions options = held_at_left_end(model);
  StaticSolver statics(model, options);
  const std::vector<Vec6> a = graded_stress(model.volume, 10.0);
  const std::vector<Vec6> b = graded_stress(model.volume, -4.0);
  const std::vector<Vec6> c = graded_stress(model.volume, 2.5);
  const StaticResult first_a = statics.solve(a);
  const StaticResult first_b = statics.solve(b);
  EXPECT_FALSE(first_a.remembered);
  const StaticResult again_a = statics.solve(a);
  const StaticResult again_b = statics.solve(b);
  EXPECT_TRUE(again_a.remembered);
  EXPECT_TRUE(again_b.remembered);
  EXPECT_TRUE(again_a.displacement_mm == first_a.displacement_mm);
  EXPECT_TRUE(again_b.displacement_mm == first_b.displacement_mm);
  EXPECT_EQ(statics.solves(), 2);
  (void)statics.solve(c);  // remembered now: c and b
  const StaticResult third_a = statics.solve(a);
  EXPECT_FALSE(third_a.remembered);
  EXPECT_EQ(statics.solves(), 4);
  EXPECT_LT(max_difference_mm(third_a.displacement_mm, first_a.displacement_mm), 1e-12 * max_norm_mm(first_a.displacement_mm));

  StaticSolver one_shot(model, options);  // solve_static's use: nothing kept
  (void)one_shot.solve_once(a);
  EXPECT_FALSE(one_shot.solve(a).remembered);
  EXPECT_EQ(one_shot.solves(), 2);
}

TEST(StaticSolver, NoLoadNeedsNoSolveAndMovesNothing) {
  const TissueModel model = test::make_box_model({3, 3, 3}, 2.0);
  StaticOptions options;
  options.solver = SolverKind::multigrid_cg;
  StaticSolver statics(model, options);
  const StaticResult r = statics.solve(std::vector<Vec6>(static_cast<std::size_t>(model.volume.cell_count()), Vec6::Zero()));
  EXPECT_EQ(max_norm_mm(r.displacement_mm), 0.0);
  EXPECT_EQ(r.report.iterations, 0);
  EXPECT_EQ(statics.solves(), 0);
  EXPECT_FALSE(statics.set_up());
}

// A stress whose forces overflow (the library's API takes any finite value; the case file stops at
// 1e9 kPa) is named, not solved into "did not converge: relative residual nan" or a zero field.
TEST(StaticSolver, ALoadThatOverflowsIsNamed) {
  const TissueModel model = test::make_box_model({3, 3, 3}, 2.0);
  StaticOptions options;
  options.solver = SolverKind::multigrid_cg;
  StaticSolver statics(model, options);
  std::vector<Vec6> stress = graded_stress(model.volume, 1.0);
  stress[5][0] = 1e308;
  try {
    (void)statics.solve(stress);
    FAIL() << "expected a ComputeError";
  } catch (const ComputeError& e) {
    EXPECT_STREQ(e.what(), "static solve: the load overflows double precision (largest residual stress 1e+308 kPa); expected finite "
                           "stresses of at most 1e+09 kPa and finite external forces");
  }
  EXPECT_EQ(statics.solves(), 0);
  // The solver stays usable: a sane stress afterwards is solved as by a fresh solver.
  const StaticResult sane = statics.solve(graded_stress(model.volume, 1.0));
  EXPECT_GT(max_norm_mm(sane.displacement_mm), 0.0);
  EXPECT_EQ(max_difference_mm(sane.displacement_mm, solve_static(model, graded_stress(model.volume, 1.0), options).displacement_mm), 0.0);
}

}  // namespace
}  // namespace cleave
