// All solvers give the same displacement on a cut, clamped plate (issue 3: agreement to the solver
// tolerance), and the shared contract: warm start, non-convergence reported, never NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/solve/linear_solver.hpp"
#include "cleave/solve/multigrid_cg_solver.hpp"
#include "cleave/solve/sparse_multiply.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

constexpr double kTightTolerance = 1e-10;
constexpr double kAgreement = 1e-6;

SolveSettings tight() {
  SolveSettings s;
  s.relative_tolerance = kTightTolerance;
  s.max_iterations = 5000;
  return s;
}

Vector solve_with(SolverKind kind, const test::LinearSystem& s, const LinkedVolume& volume, SolveReport& report) {
  auto solver = make_linear_solver(kind, tight());
  solver->setup(s.a, volume);
  Vector x = Vector::Zero(s.b.size());
  report = solver->solve(s.b, x);
  return x;
}

TEST(SolverAgreement, MultigridEigenCgAndCholmodAgreeOnPartiallyCutPlate) {
  TissueModel model = test::make_box({24, 12, 3}, 2.5);
  test::cut_across_middle(model, 8);  // 2/3 of the width
  ASSERT_EQ(model.volume.component_count(), 1);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  SolveReport mg, cg, direct;
  const Vector x_mg = solve_with(SolverKind::multigrid_cg, s, model.volume, mg);
  const Vector x_cg = solve_with(SolverKind::eigen_cg, s, model.volume, cg);
  const Vector x_direct = solve_with(SolverKind::cholmod, s, model.volume, direct);
  std::printf("partially cut plate: multigrid %d iterations, eigen-cg %d, cholmod %d\n", mg.iterations, cg.iterations,
              direct.iterations);
  for (const SolveReport* r : {&mg, &cg, &direct}) {
    EXPECT_TRUE(r->converged);
    EXPECT_LE(r->relative_residual, kTightTolerance);
  }
  EXPECT_LT((x_mg - x_direct).norm() / x_direct.norm(), kAgreement);
  EXPECT_LT((x_cg - x_direct).norm() / x_direct.norm(), kAgreement);
  // The cut opens: vertices split on the cut plane move apart.
  EXPECT_GT(model.volume.vertex_count(), (24 + 1) * (12 + 1) * (3 + 1));
}

// setup_taking() takes the caller's matrix instead of copying it (a second ~1 GB at 350k cells;
// Eigen 3.4's SparseMatrix has no move, so std::move alone would copy): the caller's matrix is
// left empty, and each solver solves the system it took as it solves one set up by copy.
TEST(SolverAgreement, SetupTakingUsesTheCallersMatrixWithoutACopy) {
  const TissueModel model = test::make_box({12, 6, 2}, 2.5);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  for (const SolverKind kind : {SolverKind::multigrid_cg, SolverKind::eigen_cg, SolverKind::cholmod}) {
    SolveReport copied_report;
    const Vector copied = solve_with(kind, s, model.volume, copied_report);
    auto solver = make_linear_solver(kind, tight());
    SparseMatrix given = s.a;
    solver->setup_taking(std::move(given), model.volume);
    EXPECT_EQ(given.nonZeros(), 0) << solver->name();
    Vector x = Vector::Zero(s.b.size());
    const SolveReport report = solver->solve(s.b, x);
    EXPECT_TRUE(report.converged) << solver->name();
    EXPECT_EQ(report.iterations, copied_report.iterations) << solver->name();
    EXPECT_EQ(x, copied) << solver->name();
  }
}

TEST(SolverAgreement, WarmStartFromTheSolutionNeedsNoIteration) {
  const TissueModel model = test::make_box({12, 6, 2}, 2.5);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  for (const SolverKind kind : {SolverKind::multigrid_cg, SolverKind::eigen_cg}) {
    auto solver = make_linear_solver(kind, tight());
    solver->setup(s.a, model.volume);
    Vector x = Vector::Zero(s.b.size());
    const SolveReport first = solver->solve(s.b, x);
    ASSERT_TRUE(first.converged) << solver->name();
    EXPECT_GT(first.iterations, 0) << solver->name();
    const SolveReport second = solver->solve(s.b, x);
    EXPECT_TRUE(second.converged) << solver->name();
    EXPECT_EQ(second.iterations, 0) << solver->name();
  }
}

TEST(SolverAgreement, NonConvergenceIsReportedWithTheResidualAndNoNaN) {
  const TissueModel model = test::make_box({12, 6, 2}, 2.5);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  SolveSettings starved;
  starved.relative_tolerance = 1e-14;
  starved.max_iterations = 1;
  for (const SolverKind kind : {SolverKind::multigrid_cg, SolverKind::eigen_cg}) {
    auto solver = make_linear_solver(kind, starved);
    solver->setup(s.a, model.volume);
    Vector x = Vector::Zero(s.b.size());
    const SolveReport r = solver->solve(s.b, x);
    EXPECT_FALSE(r.converged) << solver->name();
    EXPECT_EQ(r.iterations, 1) << solver->name();
    EXPECT_GT(r.relative_residual, starved.relative_tolerance) << solver->name();
    EXPECT_TRUE(x.allFinite()) << solver->name();
    // The residual reported is the true one of the x handed back (up to the rounding of b - A x,
    // which is relative to ||b||: the solver sums A x by 3x3 blocks, Eigen here by rows).
    EXPECT_NEAR(r.relative_residual, (s.b - s.a * x).norm() / s.b.norm(), 1e-11) << solver->name();
  }
}

TEST(SolverAgreement, NaNRightHandSideGivesNoNaN) {
  const TissueModel model = test::make_box({6, 4, 2}, 2.5);
  test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  s.b[7] = std::nan("");
  for (const SolverKind kind : {SolverKind::multigrid_cg, SolverKind::eigen_cg, SolverKind::cholmod}) {
    auto solver = make_linear_solver(kind, tight());
    solver->setup(s.a, model.volume);
    Vector x = Vector::Zero(s.b.size());
    const SolveReport r = solver->solve(s.b, x);
    EXPECT_FALSE(r.converged) << solver->name();
    EXPECT_TRUE(x.allFinite()) << solver->name();
  }
}

TEST(SolverAgreement, CholmodNamesTheDofOfASingularMatrix) {
  const TissueModel model = test::make_box({4, 3, 2}, 2.5);
  test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  // Vertex 7 loses all stiffness (as a vertex of no cell would): its dofs have zero pivots.
  const Eigen::Index dof = 3 * 7 + 1;
  for (Eigen::Index row = 0; row < s.a.outerSize(); ++row)
    for (SparseMatrix::InnerIterator it(s.a, row); it; ++it)
      if (it.row() == dof || it.col() == dof) it.valueRef() = 0;
  auto solver = make_linear_solver(SolverKind::cholmod, tight());
  try {
    solver->setup(s.a, model.volume);
    FAIL() << "expected ComputeError";
  } catch (const ComputeError& e) {
    EXPECT_NE(std::string(e.what()).find("cholmod: matrix is not positive definite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dof 22 of vertex 7"), std::string::npos) << e.what();
  }
}

// CHOLMOD with the single-precision copy of its factor (the studio's preview): one substitution
// where it meets the tolerance, refinements with double residuals where it does not, and the
// double factor where three do not; each result is the double solve's to its tolerance.
TEST(SolverAgreement, CholmodWithTheSinglePrecisionFactorRefinesToTheTolerance) {
  TissueModel model = test::make_box({12, 10, 8}, 2.5);
  test::cut_across_middle(model, 5);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  SolveReport exact_report;
  const Vector exact = solve_with(SolverKind::cholmod, s, model.volume, exact_report);
  ASSERT_EQ(exact_report.iterations, 1);
  const auto single_solve = [&](double tolerance, SolveReport& report) {
    SolveSettings settings;
    settings.relative_tolerance = tolerance;
    settings.single_precision_factor = true;
    auto solver = make_linear_solver(SolverKind::cholmod, settings);
    solver->setup(s.a, model.volume);
    Vector x = Vector::Zero(s.b.size());
    report = solver->solve(s.b, x);
    return x;
  };
  SolveReport picture, refined, unreachable;
  const Vector x_picture = single_solve(1e-3, picture);
  EXPECT_EQ(picture.iterations, 1);  // one float substitution meets it (measured 1.1e-4 on this block)
  EXPECT_TRUE(picture.converged);
  EXPECT_LE(picture.relative_residual, 1e-3);
  EXPECT_GT(picture.relative_residual, 1e-12);  // the float factor's, not the double one's
  EXPECT_LT((x_picture - exact).norm() / exact.norm(), 1e-3);

  const Vector x_refined = single_solve(1e-9, refined);
  EXPECT_EQ(refined.iterations, 2);  // one refinement (measured 1.4e-11)
  EXPECT_TRUE(refined.converged);
  EXPECT_LE(refined.relative_residual, 1e-9);
  EXPECT_LT((x_refined - exact).norm() / exact.norm(), 1e-7);

  // Below what float refinement reaches: three float substitutions, then the double factor, whose
  // solution is the plain solve's bit for bit.
  const Vector x_unreachable = single_solve(1e-30, unreachable);
  EXPECT_EQ(unreachable.iterations, 4);
  EXPECT_FALSE(unreachable.converged);
  EXPECT_EQ(x_unreachable, exact);
}

// The preview's load lives at the incisions, with rounding-size forces elsewhere (an equilibrated
// stress's residual). The first float substitution leaves out the smallest entries while their
// norm stays below a hundredth of the tolerance: one substitution still meets the tolerance
// against the whole load, and a load whose small part is not that small is not cut.
TEST(SolverAgreement, CholmodLeavesOutOnlyALoadsNegligibleEntriesInItsFirstFloatSubstitution) {
  TissueModel model = test::make_box({12, 10, 8}, 2.5);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const double tolerance = 1e-3;
  SolveSettings settings;
  settings.relative_tolerance = tolerance;
  settings.single_precision_factor = true;
  auto solver = make_linear_solver(SolverKind::cholmod, settings);
  solver->setup(s.a, model.volume);
  const Eigen::Index n = s.b.size();
  const Vector spread = Vector::Random(n);
  Vector local = Vector::Zero(n);
  for (Eigen::Index k = n - 60; k < n; ++k) local[k] = 1.0 + 0.5 * spread[k];  // the far end's vertices
  auto exact_solver = make_linear_solver(SolverKind::cholmod);
  exact_solver->setup(s.a, model.volume);
  for (const double noise : {1e-9, 1e-2}) {
    const Vector b = local + noise * spread;
    Vector x = Vector::Zero(n);
    const SolveReport report = solver->solve(b, x);
    EXPECT_TRUE(report.converged) << noise;
    EXPECT_EQ(report.iterations, 1) << noise;
    Vector r;
    residual(s.a, b, x, r);
    EXPECT_LE(r.norm(), tolerance * b.norm()) << noise;
    // At 1e-2 the noise moves every dof by far more than this: x must have kept it.
    Vector exact = Vector::Zero(n);
    exact_solver->solve(b, exact);
    EXPECT_LT((x - exact).norm(), 1e-4 * exact.norm()) << noise;
  }
}

// A load beyond float's range (|b| up to 1e40 or 1e100, > 3.4e38) cannot go through the float factor: the
// solver checks before the first float substitution, counts none, and solves with the double
// factor, bit for bit as without the float copy. A load just inside float's range still takes
// the float path.
TEST(SolverAgreement, CholmodSolvesALoadBeyondFloatsRangeWithTheDoubleFactor) {
  TissueModel model = test::make_box({12, 10, 8}, 2.5);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  SolveSettings settings;
  settings.relative_tolerance = 1e-3;
  settings.single_precision_factor = true;
  auto single = make_linear_solver(SolverKind::cholmod, settings);
  single->setup(s.a, model.volume);
  settings.single_precision_factor = false;
  auto plain = make_linear_solver(SolverKind::cholmod, settings);
  plain->setup(s.a, model.volume);
  for (const double scale : {1e100, 1e40}) {
    const Vector b = scale * s.b / s.b.cwiseAbs().maxCoeff();
    Vector x = Vector::Zero(b.size()), exact = Vector::Zero(b.size());
    const SolveReport report = single->solve(b, x);
    plain->solve(b, exact);
    EXPECT_EQ(report.iterations, 1) << scale << ": no float substitution, one double one";
    EXPECT_TRUE(report.converged) << scale;
    EXPECT_TRUE(x.allFinite()) << scale;
    EXPECT_EQ(x, exact) << scale;
  }
  const Vector inside = 1e30 * s.b / s.b.cwiseAbs().maxCoeff();
  Vector x = Vector::Zero(inside.size()), exact = Vector::Zero(inside.size());
  const SolveReport report = single->solve(inside, x);
  plain->solve(inside, exact);
  EXPECT_TRUE(report.converged);
  EXPECT_NE(x, exact) << "within float's range: the float factor's solution, not the double one's";
  EXPECT_LT((x - exact).norm(), 1e-3 * exact.norm());
}

TEST(SolverFactory, NamesRoundTripAndUnknownNamesAreListed) {
  for (const SolverKind kind : {SolverKind::multigrid_cg, SolverKind::eigen_cg, SolverKind::cholmod}) {
    EXPECT_EQ(solver_kind_from_name(solver_kind_name(kind)), kind);
    EXPECT_EQ(make_linear_solver(kind)->name(), solver_kind_name(kind));
  }
  EXPECT_EQ(solver_kind_name(SolverKind::eigen_cg), "eigen-cg");
  try {
    solver_kind_from_name("gmres");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown solver 'gmres'; expected one of multigrid, eigen-cg, cholmod");
  }
}

}  // namespace
}  // namespace cleave

namespace cleave {
namespace {

// The multigrid cycle in single precision (the default) and in double precision (the fallback
// for ill-conditioned systems) give the same solution to the solver tolerance, with about as
// many iterations: the outer double CG absorbs the float rounding of a well-posed system.
TEST(SolverAgreement, SingleAndDoublePrecisionCyclesAgree) {
  TissueModel model = test::make_box({32, 16, 4}, 1.0);  // 8,400 dofs: four levels
  test::cut_across_middle(model, 10);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::both_ends);
  std::vector<Vector> results;
  std::vector<int> iterations;
  for (const CyclePrecision precision : {CyclePrecision::single_precision, CyclePrecision::double_precision}) {
    MultigridOptions options;
    options.precision = precision;
    auto solver = make_multigrid_cg_solver(tight(), options);
    solver->setup(s.a, model.volume);
    Vector x = Vector::Zero(s.b.size());
    const SolveReport r = solver->solve(s.b, x);
    EXPECT_TRUE(r.converged);
    EXPECT_LE(r.relative_residual, kTightTolerance);
    results.push_back(x);
    iterations.push_back(r.iterations);
  }
  std::printf("partially cut plate: %d iterations with the float cycle, %d with the double cycle\n", iterations[0], iterations[1]);
  EXPECT_LT((results[0] - results[1]).norm() / results[1].norm(), kAgreement);
  EXPECT_LE(iterations[0], iterations[1] + 3);
}

// A solve that needs more than one round of the float cycle (40 iterations) but keeps cutting the
// residual goes on in single precision: the double cycle (twice the bytes per iteration, and a
// double copy of every level) is for float rounding that stalls a round.
TEST(SolverAgreement, ASlowButSteadyFloatCycleStaysInSinglePrecision) {
  // A slender cantilever and the lightest smoothing: 56 iterations to 1e-10. The multigrid's weak
  // pieces are off, and its levels go down to 30 dofs whatever their factors cost: this is about
  // the float cycle's rounds (an earlier rule that took the box's corner cells for pieces made it
  // converge in 29; a cheap factor on its second level, in 32).
  const TissueModel model = test::make_box({32, 8, 4}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  MultigridOptions options;
  options.coarsest_max_dofs = 30;
  options.coarsest_factor_share = 0;
  options.smoother.degree = 1;
  options.coarse_degree = 1;
  options.weak_pieces.max_links = 0;
  auto solver = make_multigrid_cg_solver(tight(), options);
  solver->setup(s.a, model.volume);
  Vector x = Vector::Zero(s.b.size());
  const SolveReport r = solver->solve(s.b, x);
  std::printf("slender cantilever: %d iterations, %d of them with the double cycle\n", r.iterations, r.double_cycle_iterations);
  EXPECT_TRUE(r.converged);
  EXPECT_GT(r.iterations, 40);
  EXPECT_EQ(r.double_cycle_iterations, 0);
  options.precision = CyclePrecision::double_precision;  // built in double: every iteration counts
  auto twin = make_multigrid_cg_solver(tight(), options);
  twin->setup(s.a, model.volume);
  Vector y = Vector::Zero(s.b.size());
  const SolveReport d = twin->solve(s.b, y);
  EXPECT_TRUE(d.converged);
  EXPECT_EQ(d.double_cycle_iterations, d.iterations);
  EXPECT_LT((x - y).norm() / y.norm(), kAgreement);
}

}  // namespace
}  // namespace cleave

namespace cleave {
namespace {

// update_values (the next time step: same pattern, new values) gives every solver the solution
// of the new matrix, although the multigrid keeps the coarse levels of the old one and CHOLMOD
// its symbolic analysis. A stiffness change (K -> 1.3 K, as rotations change K_R) costs the stale
// levels no iterations; a diagonal shift (a changed time step's mass term) costs many, which is
// why Dynamics sets up afresh when the time step changes; the solution is right either way.
TEST(SolverAgreement, UpdateValuesSolvesTheNewMatrix) {
  TissueModel model = test::make_box({32, 16, 4}, 1.0);
  test::cut_across_middle(model, 10);
  const test::LinearSystem old_system = test::clamped_system(model, test::Clamp::both_ends);
  struct Change {
    double scale, diagonal_shift;
  };
  for (const Change change : {Change{1.3, 0.0}, Change{1.0, 0.05}}) {
    SparseMatrix changed = old_system.a;  // same pattern
    changed *= change.scale;
    for (Eigen::Index i = 0; i < changed.rows(); ++i) changed.coeffRef(i, i) += change.diagonal_shift * old_system.a.coeff(i, i);
    changed.makeCompressed();
    SolveReport fresh_report;
    const Vector reference = solve_with(SolverKind::cholmod, {changed, old_system.b}, model.volume, fresh_report);
    solve_with(SolverKind::multigrid_cg, {changed, old_system.b}, model.volume, fresh_report);
    for (const SolverKind kind : {SolverKind::multigrid_cg, SolverKind::eigen_cg, SolverKind::cholmod}) {
      auto solver = make_linear_solver(kind, tight());
      solver->setup(old_system.a, model.volume);
      Vector x = Vector::Zero(old_system.b.size());
      solver->solve(old_system.b, x);
      x.setZero();
      solver->update_values(changed, model.volume);
      const SolveReport r = solver->solve(old_system.b, x);
      EXPECT_TRUE(r.converged) << solver->name();
      EXPECT_LT((x - reference).norm() / reference.norm(), kAgreement) << solver->name();
      std::printf("update_values (K x %.2g, diagonal + %.2g): %s %d iterations (multigrid set up afresh: %d)\n", change.scale,
                  change.diagonal_shift, std::string(solver->name()).c_str(), r.iterations, fresh_report.iterations);
      if (kind == SolverKind::multigrid_cg && change.diagonal_shift == 0.0) {
        EXPECT_LE(r.iterations, fresh_report.iterations + 3);
      }
    }
  }
}

}  // namespace
}  // namespace cleave
