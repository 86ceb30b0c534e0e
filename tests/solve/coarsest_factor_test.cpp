// The multigrid's coarsest solve: a Cholesky factor whose cost is known before it is computed,
// exact on a positive definite level, and still usable on a level a free piece makes singular.
#include "cleave/solve/coarsest_factor.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "cleave/core/error.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

TEST(CoarsestFactor, AnalysisPredictsTheFactorAndTheSolveIsExact) {
  const TissueModel model = test::make_box({6, 5, 4}, 2.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const Eigen::SparseMatrix<double> a(s.a);
  CoarsestFactor f;
  const FactorCost cost = f.analyze(a);
  // The factor holds the lower triangle at least, and at most a dense one.
  const auto n = static_cast<double>(a.rows());
  EXPECT_GE(cost.nonzeros, 0.5 * static_cast<double>(a.nonZeros() + a.rows()));
  EXPECT_LE(cost.nonzeros, 0.5 * n * (n + 1));
  EXPECT_GE(cost.flops, cost.nonzeros);
  f.factorize(a);
  EXPECT_FALSE(f.shifted());
  const Eigen::VectorXd x = f.solve(s.b);
  EXPECT_LT((a * x - s.b).norm(), 1e-12 * s.b.norm());
}

TEST(CoarsestFactor, ALevelWithAFreePieceIsFactoredShifted) {
  // No support at all: the rigid motions make the stiffness singular, and the plain Cholesky
  // factorization fails on it. The shifted LDL^T still solves a consistent load (one a
  // displacement makes, so balanced in force and moment) to a displacement that balances it.
  const TissueModel model = test::make_box({4, 3, 3}, 2.0);
  const Eigen::SparseMatrix<double> a(assemble_stiffness(model));
  const Eigen::VectorXd b = a * Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 1.0).array().sin().matrix();
  CoarsestFactor f;
  f.factorize(a);
  EXPECT_TRUE(f.shifted());
  const Eigen::VectorXd x = f.solve(b);
  ASSERT_TRUE(x.allFinite());
  EXPECT_LT((a * x - b).norm(), 1e-6 * b.norm());
}

TEST(CoarsestFactor, ARightHandSideOfAnotherSizeIsRefusedByName) {
  const TissueModel model = test::make_box({3, 3, 3}, 2.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  CoarsestFactor f;
  f.factorize(Eigen::SparseMatrix<double>(s.a));
  try {
    f.solve(Eigen::VectorXd::Zero(5));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("coarsest factor: right-hand side has 5 rows; expected {}", s.a.rows()));
  }
}

}  // namespace
}  // namespace cleave
