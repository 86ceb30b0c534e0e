// The kept forward-substituted unit columns of a low-rank update: each edit's W_C^T W_C, W_C^T y
// and y - W_C z equal those of W = L^-1 P E made whole for the same rows; columns are made once
// per row, products once per pair; past the bounds the kept batches give way.
#include "cleave/solve/forward_column_batches.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/solve/supernodal_substitution.hpp"
#include "cholmod_test_factor.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

double relative_difference(const Eigen::MatrixXd& x, const Eigen::MatrixXd& reference) {
  return (x - reference).norm() / reference.norm();
}

/// A clamped block of 10 x 10 x 12 cubes: 4,800 dofs.
test::LinearSystem block_system() {
  return test::clamped_system(test::make_box(Vec3i{10, 10, 12}, 1.0), test::Clamp::left_end);
}

/// L^-1 P E for `rows`, on all rows: the reference.
Eigen::MatrixXd whole_columns(const SupernodalSubstitution& sub, const cholmod_factor& factor, const std::vector<Eigen::Index>& rows) {
  Eigen::MatrixXd e = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(sub.order()), static_cast<Eigen::Index>(rows.size()));
  for (std::size_t c = 0; c < rows.size(); ++c) e(rows[c], static_cast<Eigen::Index>(c)) = 1.0;
  return sub.forward_of(factor, e);
}

std::vector<Eigen::Index> range(Eigen::Index first, Eigen::Index count, Eigen::Index stride = 1) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < count; ++i) rows.push_back(first + i * stride);
  return rows;
}

std::vector<Eigen::Index> joined(std::vector<Eigen::Index> a, const std::vector<Eigen::Index>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Edits as a drag makes them: a stroke's rows, then the stroke's old rows and new ones, then the
// new ones with another stroke's, the first stroke back, part of it, and all of it (all columns kept).
TEST(ForwardColumnBatches, EachEditGetsTheProductsOfItsWholeColumns) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const Eigen::Index n = s.a.rows();
  const std::vector<Eigen::Index> stroke = range(30, 12, 3), moved = range(330, 12, 3), other = range(n - 400, 10, 7);
  const std::vector<std::vector<Eigen::Index>> edits = {stroke, joined(stroke, moved), joined(moved, other), joined(other, stroke),
                                                        joined(range(36, 8, 3), other), stroke};
  const std::vector<int> made = {12, 12, 10, 0, 0, 0};
  const std::vector<std::size_t> batches = {1, 2, 3, 3, 3, 3};
  ForwardColumnBatches kept(1024, 256.0 * 1024 * 1024);
  const Eigen::MatrixXd y = Eigen::MatrixXd::Random(n, 3);
  for (std::size_t e = 0; e < edits.size(); ++e) {
    SCOPED_TRACE(e);
    const std::vector<Eigen::Index>& changed = edits[e];
    EXPECT_EQ(kept.make(sub, chol.factor(), changed), made[e]);
    EXPECT_EQ(kept.batches(), batches[e]);
    const ForwardColumnBatches::Selection edit = kept.select(changed);
    const Eigen::MatrixXd w = whole_columns(sub, chol.factor(), changed);
    EXPECT_LT(relative_difference(edit.gram(), w.transpose() * w), 1e-12);
    EXPECT_LT(relative_difference(edit.transpose_times(y), w.transpose() * y), 1e-12);
    const Eigen::MatrixXd z = Eigen::MatrixXd::Random(static_cast<Eigen::Index>(changed.size()), 3);
    Eigen::MatrixXd corrected = y;
    edit.subtract_times(corrected, z);
    EXPECT_LT(relative_difference(corrected, y - w * z), 1e-12);
  }
  EXPECT_EQ(kept.columns(), 34U);
}

// At most 40 columns beside 2 x 16 kept ones: an edit with a's rows and a third stroke's c
// forgets b's batch (unused), not a's; an edit of b alone then makes b anew and forgets a's. An
// edit that the unused batches cannot make room for (a, b and c with the bound at 40) forgets all
// and makes all its rows. Each edit's products equal those of its whole columns after the
// renumbering.
TEST(ForwardColumnBatches, KeptColumnsGiveWayPastTheBound) {
  test::LinearSystem s = block_system();
  test::CholmodFactor chol(s.a);
  const SupernodalSubstitution sub(chol.factor());
  const std::vector<Eigen::Index> a = range(10, 16, 5), b = range(900, 16, 5), c = range(2000, 16, 5);
  ForwardColumnBatches kept(40, 256.0 * 1024 * 1024);
  const auto expect_whole_products = [&](const std::vector<Eigen::Index>& changed) {
    const ForwardColumnBatches::Selection edit = kept.select(changed);
    const Eigen::MatrixXd w = whole_columns(sub, chol.factor(), changed);
    EXPECT_LT(relative_difference(edit.gram(), w.transpose() * w), 1e-12);
  };
  EXPECT_EQ(kept.make(sub, chol.factor(), a), 16);
  EXPECT_EQ(kept.make(sub, chol.factor(), b), 16);
  expect_whole_products(joined(a, b));
  EXPECT_EQ(kept.rows_to_make(c).size(), 16U);
  EXPECT_EQ(kept.rows_to_make(joined(a, c)).size(), 16U) << "b's batch gives way: only c's rows";
  EXPECT_EQ(kept.make(sub, chol.factor(), joined(a, c)), 16);
  EXPECT_EQ(kept.columns(), 32U);
  EXPECT_EQ(kept.batches(), 2U);
  expect_whole_products(joined(a, c));
  expect_whole_products(c);
  EXPECT_EQ(kept.make(sub, chol.factor(), b), 16) << "b's columns were forgotten";
  EXPECT_EQ(kept.batches(), 2U) << "a's batch, the oldest unused, gave way";
  EXPECT_EQ(kept.rows_to_make(a).size(), 16U);
  expect_whole_products(joined(c, b));
  const std::vector<Eigen::Index> all = joined(joined(c, b), a);
  EXPECT_EQ(kept.rows_to_make(all).size(), 48U) << "no unused batch to forget: all the edit's rows";
  EXPECT_EQ(kept.make(sub, chol.factor(), all), 48);
  EXPECT_EQ(kept.batches(), 1U);
  expect_whole_products(all);
  expect_whole_products(b);
  kept.clear();
  EXPECT_EQ(kept.columns(), 0U);
  EXPECT_EQ(kept.rows_to_make(a).size(), 16U);
  try {
    (void)kept.select(a);
    FAIL() << "expected InputError";
  } catch (const InputError& err) {
    EXPECT_EQ(std::string(err.what()), "forward column batches: row 10 has no column (make() them first)");
  }
}

}  // namespace
}  // namespace cleave
