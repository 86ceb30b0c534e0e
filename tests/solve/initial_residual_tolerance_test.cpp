// SolveSettings::initial_residual_tolerance: the CG solvers of cleave also stop once the residual
// is that fraction of the initial guess's residual (the dynamic step's rule), report it, and
// otherwise behave as with relative_tolerance alone. SolveSettings::zero_start_when_better: the
// guess gives way to x = 0 when it is farther from the solution in the energy norm.
#include <gtest/gtest.h>

#include "cleave/solve/conjugate_gradient.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

/// The system's solution to 1e-11 of ||b|| (multigrid CG from zero).
Vector tight_solution(const test::LinearSystem& s, const TissueModel& model) {
  SolveSettings tight;
  tight.relative_tolerance = 1e-11;
  auto solver = make_linear_solver(SolverKind::multigrid_cg, tight);
  solver->setup(s.a, model.volume);
  Vector x = Vector::Zero(s.b.size());
  EXPECT_TRUE(solver->solve(s.b, x).converged);
  return x;
}

TEST(InitialResidualTolerance, StopsAtThatFractionOfTheWarmStartResidual) {
  TissueModel model = test::make_box({12, 4, 4}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  // A good warm start: the exact solution disturbed by 1 %.
  const Vector exact = tight_solution(s, model);
  Vector start = exact;
  for (Eigen::Index i = 0; i < start.size(); ++i) start[i] *= 1.0 + 0.01 * std::sin(0.37 * static_cast<double>(i));
  const double initial = (s.b - s.a * start).norm();

  SolveSettings relative;  // 1e-8 of ||b||: many iterations from any start
  SolveSettings from_start = relative;
  from_start.initial_residual_tolerance = 1e-3;
  for (const SolverKind kind : {SolverKind::multigrid_cg}) {
    auto loose = make_linear_solver(kind, from_start);
    loose->setup(s.a, model.volume);
    Vector x = start;
    const SolveReport r = loose->solve(s.b, x);
    const double reached = (s.b - s.a * x).norm();
    EXPECT_TRUE(r.converged);
    EXPECT_LE(reached, 1e-3 * initial * (1 + 1e-9));
    EXPECT_NEAR(r.initial_relative_residual, initial / s.b.norm(), 1e-9 * initial / s.b.norm());
    EXPECT_NEAR(r.relative_residual, reached / s.b.norm(), 1e-6 * reached / s.b.norm());

    auto strict = make_linear_solver(kind, relative);
    strict->setup(s.a, model.volume);
    Vector y = start;
    const SolveReport q = strict->solve(s.b, y);
    EXPECT_TRUE(q.converged);
    EXPECT_LT(r.iterations, q.iterations);
    EXPECT_LE(q.relative_residual, 1e-8);
  }
  // Plain PCG (identity preconditioner) reads the same rule.
  Vector x = start;
  const SolveReport p = preconditioned_cg(s.a, s.b, x, IdentityPreconditioner(), from_start);
  EXPECT_TRUE(p.converged);
  EXPECT_LE((s.b - s.a * x).norm(), 1e-3 * initial * (1 + 1e-9));
}

TEST(InitialResidualTolerance, TheTighterRelativeRuleWinsWhenTheStartIsPoor) {
  // From x = 0 the initial residual is ||b||: 0.1 of it is looser than 1e-8 of ||b||, so the
  // looser (initial residual) rule applies; with 0 the relative rule alone applies.
  TissueModel model = test::make_box({8, 4, 4}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  SolveSettings off;
  SolveSettings on = off;
  on.initial_residual_tolerance = 0.1;
  Vector x0 = Vector::Zero(s.b.size()), x1 = x0;
  const SolveReport a = preconditioned_cg(s.a, s.b, x0, IdentityPreconditioner(), off);
  const SolveReport b = preconditioned_cg(s.a, s.b, x1, IdentityPreconditioner(), on);
  EXPECT_TRUE(a.converged);
  EXPECT_TRUE(b.converged);
  EXPECT_LE(a.relative_residual, 1e-8);
  EXPECT_LE(b.relative_residual, 0.1);
  EXPECT_NEAR(b.initial_relative_residual, 1.0, 1e-12);
  EXPECT_LT(b.iterations, a.iterations);
}

TEST(ZeroStartWhenBetter, KeepsAGuessCloserInEnergyEvenWithTheLargerResidual) {
  // A = diag(1, 1e4), b = (1, 0), x* = (1, 0), ||x*||_A^2 = 1. Guess (1, 1e-3): residual
  // (0, -10), ten times ||b||, but energy error 1e4 * 1e-6 = 0.01 < 1: kept. Guess (1, 0.1):
  // energy error 100 > 1: replaced by 0. Zero iterations, so x is the chosen start.
  SparseMatrix a(2, 2);
  a.insert(0, 0) = 1.0;
  a.insert(1, 1) = 1e4;
  a.makeCompressed();
  const Vector b = Vector::Unit(2, 0);
  SolveSettings settings;
  settings.max_iterations = 0;
  settings.zero_start_when_better = true;

  Vector close(2);
  close << 1.0, 1e-3;
  Vector x = close;
  SolveReport r = preconditioned_cg(a, b, x, IdentityPreconditioner(), settings);
  EXPECT_EQ(x, close);
  EXPECT_NEAR(r.initial_relative_residual, 10.0, 1e-12);

  Vector far(2);
  far << 1.0, 0.1;
  x = far;
  r = preconditioned_cg(a, b, x, IdentityPreconditioner(), settings);
  EXPECT_EQ(x, Vector::Zero(2));
  EXPECT_NEAR(r.initial_relative_residual, 1.0, 1e-12);

  settings.zero_start_when_better = false;  // off: the guess stays whatever it is
  x = far;
  r = preconditioned_cg(a, b, x, IdentityPreconditioner(), settings);
  EXPECT_EQ(x, far);
  EXPECT_NEAR(r.initial_relative_residual, 1000.0, 1e-9);
}

TEST(ZeroStartWhenBetter, TheMultigridStartsFromZeroForAnOvershootingGuessAndStopsRelativeToIt) {
  // A Newmark-like overshoot: the exact solution plus a large checkerboard (stiff) component.
  TissueModel model = test::make_box({12, 4, 4}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const Vector exact = tight_solution(s, model);
  Vector overshoot = exact;
  const double largest = exact.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < overshoot.size(); ++i) overshoot[i] += (i % 2 == 0 ? 10.0 : -10.0) * largest;
  // Multigrid CG at 1e-5 of the start's residual from the overshoot, with or without the rule.
  const auto solve_from_overshoot = [&](bool zero_start_when_better, Vector& x) {
    SolveSettings settings;
    settings.initial_residual_tolerance = 1e-5;
    settings.zero_start_when_better = zero_start_when_better;
    auto solver = make_linear_solver(SolverKind::multigrid_cg, settings);
    solver->setup(s.a, model.volume);
    x = overshoot;
    return solver->solve(s.b, x);
  };
  Vector x, y;
  const SolveReport r = solve_from_overshoot(true, x);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.initial_relative_residual, 1.0, 1e-12);  // the start was x = 0
  EXPECT_LE((s.b - s.a * x).norm(), 1e-5 * s.b.norm() * (1 + 1e-9));
  // Without it the same rule stops at 1e-5 of the overshoot's residual: a far worse solution.
  const SolveReport q = solve_from_overshoot(false, y);
  EXPECT_TRUE(q.converged);
  EXPECT_GT(q.initial_relative_residual, 100.0);
  EXPECT_GT((y - exact).norm(), 10.0 * (x - exact).norm());
}

// A solve stopped by its iteration budget (the dynamic step's iterations_per_step) reports the
// CG recurrence's residual instead of computing the true one: it must be the true one to rounding.
TEST(IterationBudget, AStopOutOfIterationsReportsTheTrueResidual) {
  TissueModel model = test::make_box({40, 6, 6}, 1.0);  // a long cantilever: several iterations
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  for (const int budget : {1, 2, 3}) {
    SolveSettings settings;
    settings.max_iterations = budget;
    auto solver = make_linear_solver(SolverKind::multigrid_cg, settings);
    solver->setup(s.a, model.volume);
    Vector x = Vector::Zero(s.b.size());
    const SolveReport r = solver->solve(s.b, x);
    const double truth = (s.b - s.a * x).norm() / s.b.norm();
    EXPECT_FALSE(r.converged);
    EXPECT_EQ(r.iterations, budget);
    EXPECT_NEAR(r.relative_residual, truth, 1e-9 * truth) << budget << " iterations";
  }
}

/// M = identity, counting its applications.
class CountingPreconditioner final : public Preconditioner {
 public:
  void apply(const Vector& r, Vector& z) const override {
    z = r;
    ++applications;
  }
  mutable int applications = 0;
};

// Each CG iteration needs one preconditioned residual for its direction, and the last iteration
// of a solve none: a solve out of iterations stops without preconditioning a residual it will
// not use (a whole V-cycle, a fifth of a dynamic step with a budget of 4), as a converged one does.
TEST(IterationBudget, NoPreconditionerApplicationIsLeftUnused) {
  TissueModel model = test::make_box({40, 6, 6}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  for (const int budget : {1, 2, 5}) {
    SolveSettings settings;
    settings.max_iterations = budget;
    CountingPreconditioner counting;
    Vector x = Vector::Zero(s.b.size());
    const SolveReport r = preconditioned_cg(s.a, s.b, x, counting, settings);
    EXPECT_FALSE(r.converged);
    EXPECT_EQ(r.iterations, budget);
    EXPECT_EQ(counting.applications, budget) << budget << " iterations";
    EXPECT_NEAR(r.relative_residual, (s.b - s.a * x).norm() / s.b.norm(), 1e-9 * r.relative_residual);
  }
  // A converged solve: as many applications as iterations, too.
  SolveSettings settings;
  settings.relative_tolerance = 1e-6;
  CountingPreconditioner counting;
  Vector x = Vector::Zero(s.b.size());
  const SolveReport r = preconditioned_cg(s.a, s.b, x, counting, settings);
  ASSERT_TRUE(r.converged);
  EXPECT_EQ(counting.applications, r.iterations);
}

}  // namespace
}  // namespace cleave
