#include "cleave/solve/block_sparse_matrix.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>
#include <utility>
#include <vector>

namespace cleave {
namespace {

constexpr int kVertices = 300;

/// 3n x 3n CSR whose stored entries come in whole 3x3 blocks (what the elements assemble), with
/// `blocks_per_row` random block columns per vertex plus the diagonal.
SparseMatrix vertex_block_matrix(int blocks_per_row, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> vertex(0, kVertices - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int v = 0; v < kVertices; ++v) {
    std::set<int> columns{v};
    for (int k = 0; k < blocks_per_row; ++k) columns.insert(vertex(rng));
    for (int w : columns)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) entries.emplace_back(3 * v + i, 3 * w + j, value(rng));
  }
  SparseMatrix a(3 * kVertices, 3 * kVertices);
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();
  return a;
}

/// 3n x 3n CSR with scattered single entries: rows of one vertex differ, blocks are partial.
SparseMatrix scattered_matrix(int entries_per_row, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> column(0, 3 * kVertices - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < 3 * kVertices; ++r)
    for (int k = 0; k < entries_per_row; ++k) entries.emplace_back(r, column(rng), value(rng));
  SparseMatrix a(3 * kVertices, 3 * kVertices);
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();
  return a;
}

std::size_t distinct_blocks(const SparseMatrix& a) {
  std::set<std::pair<int, int>> blocks;
  for (int r = 0; r < a.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a, r); it; ++it) blocks.emplace(r / 3, static_cast<int>(it.col()) / 3);
  return blocks.size();
}

void expect_same_operator(const SparseMatrix& a) {
  const BlockSparseMatrix<double> b = to_block_sparse<double>(a);
  const BlockSparseMatrix<float> f = to_block_sparse<float>(a);
  EXPECT_EQ(b.blocks(), distinct_blocks(a));
  EXPECT_EQ(b.rows(), a.rows());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::VectorXd x(a.cols());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = value(rng);
  const Eigen::VectorXd expected = a * x;
  Eigen::VectorXd y;
  multiply(b, x, y);
  EXPECT_LT((y - expected).norm(), 1e-14 * expected.norm());
  Eigen::VectorXf yf;
  multiply(f, Eigen::VectorXf(x.cast<float>()), yf);
  EXPECT_LT((yf.cast<double>() - expected).norm(), 1e-5 * expected.norm());

  // Values back into a copy of the pattern whose values were cleared: the same matrix.
  SparseMatrix back = a;
  back.coeffs().setZero();
  copy_block_values(b, back);
  EXPECT_EQ((back - a).norm(), 0.0);
  // New values on the same pattern.
  SparseMatrix doubled = 2.0 * a;
  BlockSparseMatrix<double> refreshed = b;
  refresh_block_values(doubled, refreshed);
  multiply(refreshed, x, y);
  EXPECT_LT((y - 2.0 * expected).norm(), 1e-14 * expected.norm());
}

TEST(BlockSparseMatrix, VertexBlockPatternGivesTheSameOperator) { expect_same_operator(vertex_block_matrix(8, 1)); }

TEST(BlockSparseMatrix, ScatteredEntriesWithRowsThatDifferGiveTheSameOperator) { expect_same_operator(scattered_matrix(5, 2)); }

TEST(BlockSparseMatrix, MixedBlockRowsGiveTheSameOperator) {
  // Whole blocks, plus one stray entry in every 7th row: those block rows leave the fast path.
  SparseMatrix a = vertex_block_matrix(6, 3);
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < a.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a, r); it; ++it) entries.emplace_back(r, static_cast<int>(it.col()), it.value());
  for (int r = 0; r < a.rows(); r += 7) entries.emplace_back(r, (5 * r + 1) % a.cols(), 0.5);
  SparseMatrix mixed(a.rows(), a.cols());
  mixed.setFromTriplets(entries.begin(), entries.end());
  mixed.makeCompressed();
  expect_same_operator(mixed);
}

// Back to scalar CSR: the same matrix, entry for entry, with the blocks' zeros stored (scattered
// entries leave most of each block empty).
TEST(BlockSparseMatrix, ScalarCopyOfTheBlocksIsTheMatrix) {
  for (const SparseMatrix& a : {vertex_block_matrix(4, 5), scattered_matrix(3, 6)}) {
    const BlockSparseMatrix<double> b = to_block_sparse<double>(a);
    const SparseMatrix back = to_scalar_sparse(b);
    EXPECT_TRUE(back.isCompressed());
    EXPECT_EQ(back.nonZeros(), static_cast<Eigen::Index>(b.values.size()));
    EXPECT_EQ(Eigen::MatrixXd(back), Eigen::MatrixXd(a));
  }
}

}  // namespace
}  // namespace cleave
