// The parallel substitution with a CHOLMOD supernodal factor: the same solution as
// cholmod_solve, on systems whose schedule has independent subtrees, large top supernodes
// (the blocked, parallel path), several elimination-tree roots and a single supernode.
#include "cleave/solve/supernodal_substitution.hpp"

#include <algorithm>
#include <string>
#include <vector>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "cleave/core/error.hpp"
#include "cholmod_test_factor.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

double relative_difference(const Eigen::MatrixXd& x, const Eigen::MatrixXd& reference) {
  return (x - reference).norm() / reference.norm();
}

Eigen::MatrixXd substituted(const SupernodalSubstitution& s, const cholmod_factor& f, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd x = b;
  s.solve(f, x);
  return x;
}

/// A clamped block of 12 x 12 x 14 cubes: 7,800 dofs, a top separator of several hundred columns.
test::LinearSystem block_system() {
  return test::clamped_system(test::make_box(Vec3i{12, 12, 14}, 1.0), test::Clamp::left_end);
}

TEST(SupernodalSubstitution, EqualsCholmodSolveWithSubtreesAndLargeTopSupernodes) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  EXPECT_GE(sub.subtree_count(), 2U);
  EXPECT_GE(sub.top_supernode_count(), 1U);
  EXPECT_EQ(sub.order(), static_cast<std::size_t>(s.a.rows()));
  const Eigen::MatrixXd reference = chol.cholmod_solution(s.b);
  const Eigen::MatrixXd x = substituted(sub, chol.factor(), s.b);
  EXPECT_LT(relative_difference(x, reference), 1e-12);
  EXPECT_LT((s.a * x - s.b).norm() / s.b.norm(), 1e-10);

  Eigen::MatrixXd several = Eigen::MatrixXd::Random(s.a.rows(), 3);
  EXPECT_LT(relative_difference(substituted(sub, chol.factor(), several), chol.cholmod_solution(several)), 1e-12);
}

// Two to eight columns take the narrow kernels on rows (narrow_panel_kernels.hpp), one and nine
// Eigen's products: every count agrees with cholmod_solve, through the blocked large supernodes.
TEST(SupernodalSubstitution, EqualsCholmodSolveForOneToNineColumns) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  for (Eigen::Index columns = 1; columns <= 9; ++columns) {
    const Eigen::MatrixXd b = Eigen::MatrixXd::Random(s.a.rows(), columns);
    EXPECT_LT(relative_difference(substituted(sub, chol.factor(), b), chol.cholmod_solution(b)), 1e-12) << columns << " columns";
    const Eigen::MatrixXd y = sub.forward_of(chol.factor(), b);
    EXPECT_LT(relative_difference(sub.backward_of(chol.factor(), y), chol.cholmod_solution(b)), 1e-12) << columns << " columns";
  }
}

// The same schedule gives the same bits however the threads share the work: repeated solves,
// and a solve on one thread (the equilibration's stopping test sits near rounding, so a
// scheduling-dependent result would change its iteration count from run to run).
TEST(SupernodalSubstitution, GivesTheSameBitsOnAnyNumberOfThreads) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const Eigen::MatrixXd all_threads = substituted(sub, chol.factor(), s.b);
  for (int repeat = 0; repeat < 5; ++repeat) EXPECT_TRUE(substituted(sub, chol.factor(), s.b) == all_threads);
  const Eigen::MatrixXd six = Eigen::MatrixXd::Random(s.a.rows(), 6);  // the narrow kernels' reductions too
  const Eigen::MatrixXd six_all_threads = substituted(sub, chol.factor(), six);
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  EXPECT_TRUE(substituted(sub, chol.factor(), s.b) == all_threads);
  EXPECT_TRUE(substituted(sub, chol.factor(), six) == six_all_threads);
}

TEST(SupernodalSubstitution, KeepsItsScheduleAcrossRefactorizations) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  for (Eigen::Index k = 0; k < s.a.outerSize(); ++k)  // new values, same pattern: K + K's diagonal
    for (SparseMatrix::InnerIterator it(s.a, k); it; ++it)
      if (it.row() == it.col()) it.valueRef() *= 2.0;
  chol.refactor();
  EXPECT_LT(relative_difference(substituted(sub, chol.factor(), s.b), chol.cholmod_solution(s.b)), 1e-12);
}

TEST(SupernodalSubstitution, ForwardThenBackwardIsTheSolve) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(s.a.rows(), 4);
  const Eigen::MatrixXd y = sub.forward_of(chol.factor(), b);
  // y = L^-1 P b: ||y||^2 = b^T A^-1 b, column by column.
  const Eigen::MatrixXd x = sub.backward_of(chol.factor(), y);
  EXPECT_TRUE(x == substituted(sub, chol.factor(), b)) << "the same operations as solve";
  for (Eigen::Index c = 0; c < b.cols(); ++c) EXPECT_NEAR(y.col(c).squaredNorm(), b.col(c).dot(x.col(c)), 1e-10 * y.col(c).squaredNorm());
}

// The forward-substituted unit columns W = L^-1 P E of a few rows at one end of the block: their
// Gram matrix is E^T A^-1 E (what full solves of the unit columns give), W z goes back to A^-1 E z,
// and only the supernodes above those rows are touched; the back substitution of those rows alone
// gives them the whole one's values.
TEST(SupernodalSubstitution, UnitColumnsReachOnlyTheSupernodesAboveThem) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const Eigen::Index n = s.a.rows();
  const std::vector<Eigen::Index> rows = {n - 1, n - 2, n - 30, n - 31, n - 200, n - 201, n - 202};
  std::vector<Eigen::Index> reached;
  const Eigen::MatrixXd w = sub.forward_unit_columns(chol.factor(), rows, reached);
  ASSERT_EQ(w.rows(), static_cast<Eigen::Index>(reached.size()));
  ASSERT_EQ(w.cols(), static_cast<Eigen::Index>(rows.size()));
  EXPECT_LT(reached.size(), static_cast<std::size_t>(n) / 2) << "the rows of one end reach part of the factor";
  EXPECT_TRUE(std::is_sorted(reached.begin(), reached.end()));

  Eigen::MatrixXd e = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(rows.size()));
  for (std::size_t c = 0; c < rows.size(); ++c) e(rows[c], static_cast<Eigen::Index>(c)) = 1.0;
  const Eigen::MatrixXd columns = chol.cholmod_solution(e);  // A^-1 E
  const Eigen::MatrixXd gram_reference = e.transpose() * columns;
  EXPECT_LT(relative_difference(w.transpose() * w, gram_reference), 1e-12);

  Eigen::MatrixXd w_full = Eigen::MatrixXd::Zero(n, w.cols());
  for (std::size_t i = 0; i < reached.size(); ++i) w_full.row(reached[i]) = w.row(static_cast<Eigen::Index>(i));
  EXPECT_LT(relative_difference(w_full, sub.forward_of(chol.factor(), e)), 1e-12) << "W is zero off the reached rows";
  const Eigen::VectorXd z = Eigen::VectorXd::LinSpaced(w.cols(), 1.0, 2.0);
  EXPECT_LT(relative_difference(sub.backward_of(chol.factor(), w_full * z), columns * z), 1e-12);

  // The back substitution of some rows only: the same values as the whole one's.
  const Eigen::MatrixXd y = sub.forward_of(chol.factor(), Eigen::MatrixXd::Random(n, 3));
  const Eigen::MatrixXd x = sub.backward_of(chol.factor(), y);
  const Eigen::MatrixXd x_rows = sub.backward_rows(chol.factor(), y, rows);
  ASSERT_EQ(x_rows.rows(), static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i)
    EXPECT_LT((x_rows.row(static_cast<Eigen::Index>(i)) - x.row(rows[i])).norm(), 1e-12 * x.norm()) << "row " << rows[i];
  try {
    sub.forward_unit_columns(chol.factor(), {n}, reached);
    FAIL() << "expected InputError";
  } catch (const InputError& err) {
    EXPECT_EQ(std::string(err.what()), fmt::format("supernodal substitution: row {} is outside 0 to {}", n, n - 1));
  }
  try {
    (void)sub.backward_rows(chol.factor(), y, {-1});
    FAIL() << "expected InputError";
  } catch (const InputError& err) {
    EXPECT_EQ(std::string(err.what()), fmt::format("supernodal substitution: row -1 is outside 0 to {}", n - 1));
  }
}

// A dragged stroke's tens of unit columns are split into one block of columns per thread: in an
// arena of two threads (whatever this machine has) and of one, W is L^-1 P E on the reached rows.
TEST(SupernodalSubstitution, ManyUnitColumnsSplitOverThreadsGiveTheSameColumns) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const Eigen::Index n = s.a.rows();
  std::vector<Eigen::Index> rows;
  for (Eigen::Index k = 0; k < 40; ++k) rows.push_back(n - 1 - 7 * k);  // 40 columns: two blocks of 20
  Eigen::MatrixXd e = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(rows.size()));
  for (std::size_t c = 0; c < rows.size(); ++c) e(rows[c], static_cast<Eigen::Index>(c)) = 1.0;
  const Eigen::MatrixXd reference = sub.forward_of(chol.factor(), e);
  for (const int threads : {2, 1}) {
    std::vector<Eigen::Index> reached;
    Eigen::MatrixXd w;
    tbb::task_arena(threads).execute([&] { w = sub.forward_unit_columns(chol.factor(), rows, reached); });
    Eigen::MatrixXd w_full = Eigen::MatrixXd::Zero(n, w.cols());
    for (std::size_t i = 0; i < reached.size(); ++i) w_full.row(reached[i]) = w.row(static_cast<Eigen::Index>(i));
    EXPECT_LT(relative_difference(w_full, reference), 1e-13) << threads << " thread(s)";
  }
}

TEST(SupernodalSubstitution, SolvesMatricesWithManyRootsAndWithOneSupernode) {
  // Held dofs are identity rows: each is a root of the elimination tree on its own.
  test::LinearSystem clamped = test::clamped_system(test::make_box(Vec3i{6, 3, 3}, 1.0), test::Clamp::both_ends);
  test::CholmodFactor chol(clamped.a);
  const SupernodalSubstitution sub(chol.factor());
  EXPECT_LT(relative_difference(substituted(sub, chol.factor(), clamped.b), chol.cholmod_solution(clamped.b)), 1e-12);

  SparseMatrix one(1, 1);
  one.insert(0, 0) = 4.0;
  one.makeCompressed();
  test::CholmodFactor single(one);
  const SupernodalSubstitution sub_single(single.factor());
  Eigen::MatrixXd b(1, 2);
  b << 2.0, -8.0;
  const Eigen::MatrixXd x = substituted(sub_single, single.factor(), b);
  EXPECT_DOUBLE_EQ(x(0, 0), 0.5);
  EXPECT_DOUBLE_EQ(x(0, 1), -2.0);
}

// The single-precision copy of the factor: the same schedule (subtrees, blocked large top
// supernodes) on float values and vectors. Its error is float rounding times the condition
// number: small, but not the double solve's (which would mean the copy was never read).
TEST(SupernodalSubstitution, SolvesInSinglePrecisionWithTheFactorsFloatCopy) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const std::vector<float> values = sub.single_precision_values(chol.factor());
  ASSERT_EQ(values.size(), chol.factor().xsize);
  const double* exact = static_cast<const double*>(chol.factor().x);
  for (std::size_t i = 0; i < values.size(); i += 997) EXPECT_EQ(values[i], static_cast<float>(exact[i]));

  const Eigen::MatrixXd reference = chol.cholmod_solution(s.b);
  Eigen::MatrixXd x = s.b;
  sub.solve_single(chol.factor(), values, x);
  const double error = relative_difference(x, reference);
  EXPECT_LT(error, 1e-4);   // measured 1.0e-7
  EXPECT_GT(error, 1e-10);  // float arithmetic, not the double factor
  // Several columns (the wide kernels) solve each column alike.
  const Eigen::MatrixXd several = Eigen::MatrixXd::Random(s.a.rows(), 3);
  Eigen::MatrixXd several_x = several;
  sub.solve_single(chol.factor(), values, several_x);
  EXPECT_LT(relative_difference(several_x, chol.cholmod_solution(several)), 1e-4);

  const std::vector<float> short_copy(values.begin(), values.end() - 1);
  try {
    sub.solve_single(chol.factor(), short_copy, x);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("supernodal substitution: {} single-precision values for a factor of {}; "
                                                 "expected a copy made by single_precision_values of this factor",
                                                 values.size() - 1, values.size()));
  }
}

// A load on a few rows (the incisions' released traction): the forward sweep skips the
// supernodes below none of them, whose rows stay zero, so the result is solve_single's bit for
// bit; entries outside the support are not read.
TEST(SupernodalSubstitution, SolvesALoadOnFewRowsLikeTheWholeSolveVisitingOnlyTheSupernodesAboveThem) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const std::vector<float> values = sub.single_precision_values(chol.factor());
  const Eigen::Index n = s.a.rows();
  const std::vector<Eigen::Index> support = {3, 4, 5, 100, 101, 102, n / 2, n - 10};
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n, 1);
  for (const Eigen::Index r : support) b(r, 0) = 1.0 + 0.01 * static_cast<double>(r);
  Eigen::MatrixXd whole = b;
  sub.solve_single(chol.factor(), values, whole);
  Eigen::MatrixXd supported = Eigen::MatrixXd::Constant(n, 1, 1e3);  // not read outside the support
  for (const Eigen::Index r : support) supported(r, 0) = b(r, 0);
  sub.solve_single_supported(chol.factor(), values, support, supported);
  EXPECT_TRUE(supported == whole);
  EXPECT_LT(relative_difference(supported, chol.cholmod_solution(b)), 1e-4);
  try {
    sub.solve_single_supported(chol.factor(), values, {n}, supported);
    FAIL() << "expected InputError";
  } catch (const InputError& err) {
    EXPECT_EQ(std::string(err.what()), fmt::format("supernodal substitution: row {} is outside 0 to {}", n, n - 1));
  }
}

TEST(SupernodalSubstitution, RejectsARightHandSideOfAnotherSize) {
  test::LinearSystem s = test::clamped_system(test::make_box(Vec3i{3, 2, 2}, 1.0), test::Clamp::left_end);
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  Eigen::MatrixXd wrong = Eigen::MatrixXd::Ones(s.a.rows() + 1, 1);
  try {
    sub.solve(chol.factor(), wrong);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              fmt::format("supernodal substitution: right-hand side has {} rows and the factor order {}; the schedule was "
                          "made for order {} with {} supernodes",
                          s.a.rows() + 1, s.a.rows(), s.a.rows(), chol.factor().nsuper));
  }
}

}  // namespace
}  // namespace cleave
