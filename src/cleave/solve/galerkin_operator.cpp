#include "cleave/solve/galerkin_operator.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "cleave/core/error.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include <utility>

namespace cleave {
namespace {

constexpr std::size_t kVerticesPerTask = 256;

/// A row of 3x3 blocks keyed by column vertex, accumulated through a dense slot table that is
/// reset after each row (one per thread, so rows are built in parallel without locks).
class BlockRowAccumulator {
 public:
  explicit BlockRowAccumulator(std::size_t columns) : slot_(columns, -1) {}
  Mat3& at(VertexId column) {
    int& s = slot_[static_cast<std::size_t>(column)];
    if (s < 0) {
      s = static_cast<int>(blocks_.size());
      blocks_.push_back({column, Mat3::Zero()});
    }
    return blocks_[static_cast<std::size_t>(s)].second;
  }
  /// The row in the order its columns were first met, in a vector of its own size; the
  /// accumulator is empty afterwards and keeps its capacity (no regrowth per row).
  std::vector<std::pair<VertexId, Mat3>> take() {
    for (const auto& b : blocks_) slot_[static_cast<std::size_t>(b.first)] = -1;
    std::vector<std::pair<VertexId, Mat3>> row(blocks_.begin(), blocks_.end());
    blocks_.clear();
    return row;
  }
  /// The row sorted by column; the accumulator is empty afterwards.
  std::vector<std::pair<VertexId, Mat3>> take_sorted() {
    std::vector<std::pair<VertexId, Mat3>> row = take();
    std::sort(row.begin(), row.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    return row;
  }

 private:
  std::vector<int> slot_;
  std::vector<std::pair<VertexId, Mat3>> blocks_;
};

using BlockRows = std::vector<std::vector<std::pair<VertexId, Mat3>>>;

/// Block rows to a compressed RowMajor matrix (3 scalar rows per block row).
SparseMatrix to_sparse(const BlockRows& rows) {
  const auto n = static_cast<Eigen::Index>(3 * rows.size());
  std::vector<SparseMatrix::StorageIndex> start(rows.size() + 1, 0);
  for (std::size_t v = 0; v < rows.size(); ++v) start[v + 1] = start[v] + static_cast<SparseMatrix::StorageIndex>(9 * rows[v].size());
  SparseMatrix m(n, n);
  m.makeCompressed();
  m.resizeNonZeros(start.back());
  auto* outer = m.outerIndexPtr();
  auto* inner = m.innerIndexPtr();
  double* values = m.valuePtr();
  for (std::size_t v = 0; v < rows.size(); ++v) {
    const auto width = static_cast<SparseMatrix::StorageIndex>(3 * rows[v].size());
    for (int i = 0; i < 3; ++i) outer[3 * v + static_cast<std::size_t>(i)] = start[v] + i * width;
  }
  outer[n] = start.back();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows.size(), kVerticesPerTask), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t v = range.begin(); v < range.end(); ++v) {
      const auto& row = rows[v];
      for (int i = 0; i < 3; ++i) {
        auto k = outer[3 * v + static_cast<std::size_t>(i)];
        for (const auto& [column, block] : row)
          for (int j = 0; j < 3; ++j) {
            inner[k] = 3 * column + j;
            values[k] = block(i, j);
            ++k;
          }
      }
    }
  });
  return m;
}

}  // namespace

std::vector<std::uint8_t> identity_rows(const SparseMatrix& a) {
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(a.rows()), 0);
  const auto* outer = a.outerIndexPtr();
  const auto* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.rows(), 4096), [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index row = range.begin(); row < range.end(); ++row) {
      bool identity = true;
      bool has_diagonal = false;
      for (auto k = outer[row]; k < outer[row + 1] && identity; ++k) {
        if (inner[k] == row) {
          has_diagonal = values[k] != 0;
        } else if (values[k] != 0) {
          identity = false;
        }
      }
      fixed[static_cast<std::size_t>(row)] = identity && has_diagonal ? 1 : 0;
    }
  });
  return fixed;
}

std::vector<std::uint8_t> identity_rows(const BlockSparseMatrix<double>& a) {
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(a.rows()), 0);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.block_rows(), 1024), [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index v = range.begin(); v < range.end(); ++v) {
      const auto first = static_cast<std::size_t>(a.row_start[static_cast<std::size_t>(v)]);
      const auto last = static_cast<std::size_t>(a.row_start[static_cast<std::size_t>(v) + 1]);
      for (std::size_t i = 0; i < 3; ++i) {
        bool identity = true;
        bool has_diagonal = false;
        for (std::size_t k = first; k < last && identity; ++k)
          for (std::size_t j = 0; j < 3; ++j) {
            const double value = a.values[9 * k + 3 * i + j];
            if (a.column[k] == v && j == i) has_diagonal = value != 0;
            else if (value != 0) identity = false;
          }
        fixed[3 * static_cast<std::size_t>(v) + i] = identity && has_diagonal ? 1 : 0;
      }
    }
  });
  return fixed;
}

SparseMatrix galerkin_operator(const SparseMatrix& a, const std::vector<std::uint8_t>& fixed, const Prolongation& p) {
  return galerkin_operator(to_block_sparse<double>(a), fixed, p);
}

SparseMatrix galerkin_operator(const BlockSparseMatrix<double>& blocks, const std::vector<std::uint8_t>& fixed, const Prolongation& p) {
  const auto fine_vertices = static_cast<std::size_t>(p.fine_count());
  const auto coarse_vertices = static_cast<std::size_t>(p.coarse_count());
  if (blocks.block_rows() != static_cast<Eigen::Index>(fine_vertices) || fixed.size() != 3 * fine_vertices)
    throw InputError(fmt::format("galerkin operator: {} block rows and {} fixed flags for a prolongation from {} fine vertices; "
                                 "expected {} and {}",
                                 blocks.block_rows(), fixed.size(), fine_vertices, fine_vertices, 3 * fine_vertices));
  // A P by fine block rows: (A P)[i, J] = sum_j A[i, j] P[j, J] over free rows and columns,
  // one 3x3 block of A at a time (A as block CSR).
  BlockRows ap(fine_vertices);
  tbb::enumerable_thread_specific<BlockRowAccumulator> ap_accumulators([&] { return BlockRowAccumulator(coarse_vertices); });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, fine_vertices, kVerticesPerTask), [&](const tbb::blocked_range<std::size_t>& range) {
    BlockRowAccumulator& acc = ap_accumulators.local();
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      const Vec3 row_free(fixed[3 * i] ? 0.0 : 1.0, fixed[3 * i + 1] ? 0.0 : 1.0, fixed[3 * i + 2] ? 0.0 : 1.0);
      if (row_free.isZero()) {
        ap[i].clear();
        continue;
      }
      const bool row_all_free = row_free.minCoeff() > 0;
      for (auto k = blocks.row_start[i]; k < blocks.row_start[i + 1]; ++k) {
        const auto j = static_cast<std::size_t>(blocks.column[static_cast<std::size_t>(k)]);
        const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> stored(blocks.values.data() + 9 * static_cast<std::size_t>(k));
        Mat3 block;
        if (row_all_free && fixed[3 * j] == 0 && fixed[3 * j + 1] == 0 && fixed[3 * j + 2] == 0) {
          block = stored;  // the common case: nothing held in the row or the column
        } else {
          const Vec3 column_free(fixed[3 * j] ? 0.0 : 1.0, fixed[3 * j + 1] ? 0.0 : 1.0, fixed[3 * j + 2] ? 0.0 : 1.0);
          block = row_free.asDiagonal() * stored * column_free.asDiagonal();
        }
        if (block.isZero(0.0)) continue;
        for (int e = p.fine_start[j]; e < p.fine_start[j + 1]; ++e) {
          const auto& entry = p.by_fine[static_cast<std::size_t>(e)];
          acc.at(entry.vertex) += entry.weight * block;
        }
      }
      ap[i] = acc.take();  // A P's rows are only summed into P^T (A P): no order needed
    }
  });

  // P^T (A P) by coarse block rows; free fine rows only (fixed rows of A P are already empty).
  BlockRows coarse(coarse_vertices);
  tbb::enumerable_thread_specific<BlockRowAccumulator> accumulators([&] { return BlockRowAccumulator(coarse_vertices); });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, coarse_vertices, kVerticesPerTask), [&](const tbb::blocked_range<std::size_t>& range) {
    BlockRowAccumulator& acc = accumulators.local();
    for (std::size_t v = range.begin(); v < range.end(); ++v) {
      for (int e = p.coarse_start[v]; e < p.coarse_start[v + 1]; ++e) {
        const auto& entry = p.by_coarse[static_cast<std::size_t>(e)];
        for (const auto& [column, block] : ap[static_cast<std::size_t>(entry.vertex)]) acc.at(column) += entry.weight * block;
      }
      acc.at(static_cast<VertexId>(v));  // the diagonal block is always present
      auto row = acc.take_sorted();
      for (auto& [column, block] : row)
        if (column == static_cast<VertexId>(v))
          for (int axis = 0; axis < 3; ++axis)
            if (block(axis, axis) == 0 && block.row(axis).isZero() && block.col(axis).isZero()) block(axis, axis) = 1;
      coarse[v] = std::move(row);
    }
  });
  return to_sparse(coarse);
}

}  // namespace cleave
