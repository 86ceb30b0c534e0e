// The kept factor of the design systems after edits that change diagonal entries only (constraints
// added, removed, moved): the Woodbury update must give the solution of the edited system, keep
// its columns across edits (also those of the right-hand sides' rows, so that an edit whose rows
// all have columns needs no solve with the factor), and give way to a factorization when it cannot
// reach the tolerance.
#include <gtest/gtest.h>

#include <cstdio>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <vector>

#include "cleave/stress/sparse_cholesky.hpp"

namespace cleave {
namespace {

/// w_L L^T L of the 7-point cell Laplacian on an n x n x n block of cells, plus `constraint` on
/// the diagonal of each constrained cell: the shape of the design's direction and eigenvalue systems.
Eigen::SparseMatrix<double> design_system(int n, const std::vector<int>& constrained, double constraint) {
  const int cells = n * n * n;
  const auto id = [n](int i, int j, int k) { return i + n * (j + n * k); };
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        std::vector<int> neighbours;
        if (i > 0) neighbours.push_back(id(i - 1, j, k));
        if (i + 1 < n) neighbours.push_back(id(i + 1, j, k));
        if (j > 0) neighbours.push_back(id(i, j - 1, k));
        if (j + 1 < n) neighbours.push_back(id(i, j + 1, k));
        if (k > 0) neighbours.push_back(id(i, j, k - 1));
        if (k + 1 < n) neighbours.push_back(id(i, j, k + 1));
        const int row = id(i, j, k);
        entries.emplace_back(row, row, -1.0);
        for (const int c : neighbours) entries.emplace_back(row, c, 1.0 / static_cast<double>(neighbours.size()));
      }
  Eigen::SparseMatrix<double> l(cells, cells);
  l.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseMatrix<double> a = Eigen::SparseMatrix<double>(l.transpose()) * l;
  for (const int c : constrained) a.coeffRef(c, c) += constraint;
  a.makeCompressed();
  return a;
}

/// Right-hand sides w_C target at the constrained cells (two columns of different targets).
Eigen::MatrixXd targets(int cells, const std::vector<int>& constrained, double constraint) {
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(cells, 2);
  for (std::size_t t = 0; t < constrained.size(); ++t) {
    b(constrained[t], 0) += constraint * (1.0 + 0.1 * static_cast<double>(t));
    b(constrained[t], 1) += constraint * (t % 2 == 0 ? 1.0 : -0.5);
  }
  return b;
}

double relative_error(const Eigen::MatrixXd& x, const Eigen::MatrixXd& reference) {
  return (x - reference).norm() / reference.norm();
}

/// The largest normwise backward error ||b - a x|| / (||a||_1 ||x|| + ||b||) over the columns:
/// what solve_with_current_factor's tolerance bounds.
double backward_error(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& x, const Eigen::MatrixXd& b) {
  double a_norm = 0.0;
  for (Eigen::Index j = 0; j < a.outerSize(); ++j) a_norm = std::max(a_norm, a.col(j).cwiseAbs().sum());
  double worst = 0.0;
  for (Eigen::Index c = 0; c < b.cols(); ++c)
    worst = std::max(worst, (b.col(c) - a * x.col(c)).norm() / (a_norm * x.col(c).norm() + b.col(c).norm()));
  return worst;
}

constexpr int kSide = 12;
constexpr int kCells = kSide * kSide * kSide;
constexpr double kConstraint = 1e3;
constexpr double kTolerance = 1e-13;

/// The design system with the constraints `constrained`, solved with the kept factor: within 1e-9
/// of a direct solve and with backward error at most kTolerance.
void expect_edit_solved(const SparseCholesky& chol, const std::vector<int>& constrained, Eigen::MatrixXd& x) {
  const Eigen::SparseMatrix<double> a = design_system(kSide, constrained, kConstraint);
  const Eigen::MatrixXd b = targets(kCells, constrained, kConstraint);
  ASSERT_TRUE(chol.solve_with_current_factor(a, b, x, kTolerance, 40));
  const Eigen::MatrixXd reference = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(a).solve(b);
  EXPECT_LT(relative_error(x, reference), 1e-9);
  EXPECT_LE(backward_error(a, x, b), kTolerance);
}

TEST(SparseCholeskyUpdate, ConstraintsAddedRemovedAndMovedAreSolvedWithTheKeptFactor) {
  const std::vector<int> first = {5, 100, 333, 900, 1500};
  SparseCholesky chol;
  chol.set_update_policy(SparseCholesky::UpdatePolicy::columns);  // (the default chooses by measured cost)
  const Eigen::SparseMatrix<double> a0 = design_system(kSide, first, kConstraint);
  chol.factorize(a0);
  Eigen::MatrixXd x = chol.solve_refined(a0, targets(kCells, first, kConstraint));

  // Each edit is measured against the kept factor of `first`: added, removed, moved, and back.
  const std::vector<std::vector<int>> edits = {{5, 100, 333, 900, 1500, 17, 18, 19, 20},
                                               {5, 333, 1500, 17, 18, 19, 20},
                                               {6, 101, 334, 901, 1501},
                                               {5, 100, 333, 900, 1500, 6}};
  // Solves with the factor: the first and third edits bring rows without columns; the second and
  // fourth only rows whose columns the earlier edits made, so G alone answers them.
  const std::vector<bool> needs_solves = {true, false, true, false};
  Eigen::Index rows_before = 0;
  for (std::size_t e = 0; e < edits.size(); ++e) {
    SCOPED_TRACE(e);
    ASSERT_NO_FATAL_FAILURE(expect_edit_solved(chol, edits[e], x));
    EXPECT_EQ(chol.last_iterations(), 0);  // no CG: the update is exact
    EXPECT_EQ(chol.low_rank_solves(), static_cast<int>(e) + 1);
    EXPECT_EQ(chol.last_factor_solves() > 0, needs_solves[e]) << chol.last_factor_solves() << " solves";
    EXPECT_GE(chol.low_rank_rows(), rows_before);  // columns are kept across edits
    rows_before = chol.low_rank_rows();
  }
  // Columns: the first edit's rows, changed (17-20) or only in b (5, 100, 333, 900, 1500), and the
  // third edit's new rows 6, 101, 334, 901, 1501; the second and last edits needed no new one.
  EXPECT_EQ(chol.low_rank_rows(), 14);

  // A change of the right-hand side only (the factorized matrix, new target values on its rows):
  // every row of b has a column, so no solve either.
  Eigen::MatrixXd b0 = 2.0 * targets(kCells, first, kConstraint);
  ASSERT_TRUE(chol.solve_with_current_factor(a0, b0, x, kTolerance, 40));
  EXPECT_EQ(chol.last_factor_solves(), 0);
  EXPECT_LT(relative_error(x, Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(a0).solve(b0)), 1e-9);
  EXPECT_LE(backward_error(a0, x, b0), kTolerance);
  // ... but a right-hand side on a row without a column is solved with the factor.
  b0(1000, 1) = kConstraint;
  ASSERT_TRUE(chol.solve_with_current_factor(a0, b0, x, kTolerance, 40));
  EXPECT_GT(chol.last_factor_solves(), 0);
  EXPECT_LT(relative_error(x, Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(a0).solve(b0)), 1e-9);
  // The same system once more (an undo and a redo): its remembered solution, bit for bit.
  const Eigen::MatrixXd solved = x;
  x.setZero();
  EXPECT_EQ(chol.remembered_solves(), 0);
  ASSERT_TRUE(chol.solve_with_current_factor(a0, b0, x, kTolerance, 40));
  EXPECT_EQ(chol.remembered_solves(), 1);
  EXPECT_EQ(chol.last_factor_solves(), 0);
  EXPECT_TRUE(x == solved);

  // A new factorization drops the kept columns.
  chol.factorize(design_system(kSide, edits.back(), kConstraint));
  EXPECT_EQ(chol.low_rank_rows(), 0);
}

// The sparse update (forward-substituted unit columns of the changed rows only, no columns of G
// kept): the same edits, each the solution of its system, none of them refactorized, each making
// columns of W only for the changed rows it has none for.
TEST(SparseCholeskyUpdate, TheSparseUpdateSolvesTheSameEditsWithoutKeepingColumns) {
  const std::vector<int> first = {5, 100, 333, 900, 1500};
  SparseCholesky chol;
  chol.set_update_policy(SparseCholesky::UpdatePolicy::sparse);
  const Eigen::SparseMatrix<double> a0 = design_system(kSide, first, kConstraint);
  chol.factorize(a0);
  Eigen::MatrixXd x = chol.solve_refined(a0, targets(kCells, first, kConstraint));
  // A stroke-like edit (a row of 60 fresh cells), the constraints moved, one back, the stroke-like
  // edit again, once more (as after an undo and a redo: the remembered solution, no solve), and
  // the stroke dragged one cell further (one new column).
  std::vector<int> stroke = first;
  std::vector<int> dragged = first;
  for (int i = 0; i < 60; ++i) stroke.push_back(kSide * kSide * 6 + kSide * 3 + i);
  for (int i = 1; i <= 60; ++i) dragged.push_back(kSide * kSide * 6 + kSide * 3 + i);
  const std::vector<std::vector<int>> edits = {stroke, {6, 101, 334, 901, 1501}, {5, 100, 333, 900, 1500, 6}, stroke, stroke, dragged};
  const std::vector<bool> needs_solves = {true, true, true, true, false, true};
  const std::vector<int> sparse_solves = {1, 2, 3, 4, 4, 5};
  const std::vector<int> remembered = {0, 0, 0, 0, 1, 1};
  // (The stroke's cells 900 to 959 include a constrained cell, 900, and the moved one, 901.)
  const std::vector<int> columns_made = {60, 68, 68, 68, 68, 69};
  for (std::size_t e = 0; e < edits.size(); ++e) {
    SCOPED_TRACE(e);
    ASSERT_NO_FATAL_FAILURE(expect_edit_solved(chol, edits[e], x));
    EXPECT_EQ(chol.last_iterations(), 0);
    EXPECT_EQ(chol.sparse_update_solves(), sparse_solves[e]);
    EXPECT_EQ(chol.low_rank_solves(), sparse_solves[e]);
    EXPECT_EQ(chol.remembered_solves(), remembered[e]);
    EXPECT_EQ(chol.sparse_columns_made(), columns_made[e]);
    EXPECT_EQ(chol.last_factor_solves() > 0, needs_solves[e]) << chol.last_factor_solves() << " solves";
    // One solve: the residual the update leaves on the changed rows is corrected before the back
    // substitution (no refinement step).
    EXPECT_EQ(chol.last_factor_solves(), needs_solves[e] ? 1 : 0);
    EXPECT_EQ(chol.low_rank_rows(), 0) << "no columns of G are bought";
  }
  EXPECT_EQ(chol.reused_analyses(), 0) << "no refactorization";
}

// Edits on disjoint sets of rows whose kept columns of W together would exceed kMaxLowRankRows:
// the kept ones are forgotten (the first rows' columns are made again when they come back) and
// every edit is the solution of its system.
TEST(SparseCholeskyUpdate, KeptColumnsOfTheSparseUpdateGiveWayWhenTheyWouldExceedTheBound) {
  const std::vector<int> first = {0};
  SparseCholesky chol;
  chol.set_update_policy(SparseCholesky::UpdatePolicy::sparse);
  const Eigen::SparseMatrix<double> a0 = design_system(kSide, first, kConstraint);
  chol.factorize(a0);
  Eigen::MatrixXd x = chol.solve_refined(a0, targets(kCells, first, kConstraint));
  const int half = static_cast<int>(SparseCholesky::kMaxLowRankRows) / 2 + 10;
  ASSERT_LT(2 + 2 * half, kCells);
  // The first rows, the next ones (too many to keep both), the first ones and one more: without
  // the first rows' columns forgotten that edit would make one column.
  const std::vector<int> begins = {1, 1 + half, 1};
  const std::vector<int> extra = {0, 0, 1};
  const std::vector<int> columns_made = {half, 2 * half, 3 * half + 1};
  for (std::size_t e = 0; e < begins.size(); ++e) {
    SCOPED_TRACE(e);
    std::vector<int> cells = first;
    for (int c = begins[e]; c < begins[e] + half + extra[e]; ++c) cells.push_back(c == begins[e] + half ? 1 + 2 * half : c);
    ASSERT_NO_FATAL_FAILURE(expect_edit_solved(chol, cells, x));
    EXPECT_EQ(chol.sparse_columns_made(), columns_made[e]);
    EXPECT_EQ(chol.sparse_update_solves(), static_cast<int>(e) + 1);
  }
}

TEST(SparseCholeskyUpdate, TooManyChangedRowsFallBackToTheCaller) {
  std::vector<int> first = {0};
  SparseCholesky chol;
  const Eigen::SparseMatrix<double> a0 = design_system(kSide, first, kConstraint);
  chol.factorize(a0);
  Eigen::MatrixXd x = chol.solve_refined(a0, targets(kCells, first, kConstraint));
  // More rows than the update keeps: the kept factor alone cannot answer at once; whatever the
  // caller is told, a true answer must be the solution.
  // Rows 1 to kMaxLowRankRows + 1 change (row 0 was constrained already): one more than G may hold,
  // whatever the columns' measured cost.
  std::vector<int> many;
  for (int c = 0; c < kCells && static_cast<Eigen::Index>(many.size()) <= SparseCholesky::kMaxLowRankRows + 1; ++c) many.push_back(c);
  const Eigen::SparseMatrix<double> a = design_system(kSide, many, kConstraint);
  const Eigen::MatrixXd b = targets(kCells, many, kConstraint);
  if (chol.solve_with_current_factor(a, b, x, kTolerance, 40)) {
    EXPECT_LE(backward_error(a, x, b), kTolerance);
  }
  EXPECT_EQ(chol.low_rank_solves(), 0);
  EXPECT_EQ(chol.low_rank_rows(), 0);
}

}  // namespace
// The equilibration's CG preconditions with a single-precision copy of the factor: it solves to
// about the float rounding times the condition number, and a refactorization (same pattern, new
// values) replaces the copy, so a solve never uses the values of an earlier matrix.
TEST(SparseCholesky, SolvesInSinglePrecisionWithTheCurrentFactorsFloatCopy) {
  const std::vector<int> first{5, 300, 1200};
  const std::vector<int> second{17, 900};
  const Eigen::SparseMatrix<double> a = design_system(kSide, first, kConstraint);
  const Eigen::SparseMatrix<double> a2 = design_system(kSide, second, kConstraint);
  const Eigen::VectorXd b = targets(kCells, first, kConstraint).col(0) + Eigen::VectorXd::Ones(kCells);
  SparseCholesky chol;
  chol.factorize(a);
  const Eigen::VectorXd exact = chol.solve(b);
  const Eigen::VectorXd single = chol.solve_single_precision(b);
  const double error = relative_error(single, exact);
  std::printf("single-precision solve: relative error %.2e\n", error);
  EXPECT_LT(error, 1e-5);  // measured 2.7e-7
  EXPECT_GT(error, 1e-12);  // rounded in float, not the double factor's solve

  chol.factorize(a2);
  const Eigen::VectorXd exact2 = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(a2).solve(b);
  ASSERT_GT(relative_error(exact2, exact), 1e-2);
  const double error2 = relative_error(chol.solve_single_precision(b), exact2);
  std::printf("after the refactorization: relative error %.2e\n", error2);
  EXPECT_LT(error2, 1e-5);  // a stale copy would be off by more than 1e-2
}

}  // namespace cleave
