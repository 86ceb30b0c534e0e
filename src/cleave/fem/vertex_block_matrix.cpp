#include "cleave/fem/vertex_block_matrix.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave {

void vertex_neighbours(const LinkedVolume& volume, VertexId v, std::vector<VertexId>& out) {
  out.clear();
  for (const CellId c : volume.vertex_cells()[static_cast<std::size_t>(v)])
    for (const VertexId w : volume.cell_vertices(c)) out.push_back(w);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

namespace {

/// The block rows and columns of the current topology: rows of vertices with copied(v) take the
/// `width(v)` block columns `column_of(v, k)` of an earlier pattern (unchanged by the cuts since),
/// the others their neighbours found afresh. Shared by the block and the scalar patterns.
template <typename Copied, typename Width, typename ColumnOf>
void build_block_rows(const LinkedVolume& volume, const Copied& copied, const Width& width, const ColumnOf& column_of,
                      std::vector<std::int32_t>& row_start, std::vector<std::int32_t>& column) {
  const VertexId n = volume.vertex_count();
  volume.vertex_cells();  // build the lazy cache before the parallel loops
  row_start.assign(static_cast<std::size_t>(n) + 1, 0);
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, n), [&](const tbb::blocked_range<VertexId>& range) {
    std::vector<VertexId> neighbours;
    for (VertexId v = range.begin(); v != range.end(); ++v) {
      if (copied(v)) {
        row_start[static_cast<std::size_t>(v) + 1] = width(v);
      } else {
        vertex_neighbours(volume, v, neighbours);
        row_start[static_cast<std::size_t>(v) + 1] = static_cast<std::int32_t>(neighbours.size());
      }
    }
  });
  for (std::size_t row = 0; row < static_cast<std::size_t>(n); ++row) row_start[row + 1] += row_start[row];
  column.resize(static_cast<std::size_t>(row_start.back()));
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, n), [&](const tbb::blocked_range<VertexId>& range) {
    std::vector<VertexId> neighbours;
    for (VertexId v = range.begin(); v != range.end(); ++v) {
      auto* columns = column.data() + row_start[static_cast<std::size_t>(v)];
      if (copied(v)) {
        for (std::int32_t k = 0; k < width(v); ++k) columns[k] = column_of(v, k);
        continue;
      }
      vertex_neighbours(volume, v, neighbours);
      std::copy(neighbours.begin(), neighbours.end(), columns);
    }
  });
}

/// The scalar pattern (3 rows per block row, every entry of every block), zero except the rows
/// of unaffected vertices, whose values are copied from `previous`. `previous` is null for a
/// fresh one.
SparseMatrix build_pattern(const LinkedVolume& volume, const SparseMatrix* previous, const std::vector<std::uint8_t>* affected) {
  const auto copied = [&](VertexId v) {
    return previous != nullptr && (*affected)[static_cast<std::size_t>(v)] == 0 && 3 * v < previous->rows();
  };
  const auto width = [&](VertexId v) {
    return static_cast<std::int32_t>((previous->outerIndexPtr()[3 * v + 1] - previous->outerIndexPtr()[3 * v]) / 3);
  };
  const auto column_of = [&](VertexId v, std::int32_t k) {
    return static_cast<std::int32_t>(previous->innerIndexPtr()[previous->outerIndexPtr()[3 * v] + 3 * k] / 3);
  };
  std::vector<std::int32_t> row_start, column;
  build_block_rows(volume, copied, width, column_of, row_start, column);

  const VertexId n = volume.vertex_count();
  const auto entries = static_cast<Eigen::Index>(9 * static_cast<std::int64_t>(column.size()));
  SparseMatrix m(3 * static_cast<Eigen::Index>(n), 3 * static_cast<Eigen::Index>(n));
  m.resizeNonZeros(entries);
  auto* outer = m.outerIndexPtr();
  for (VertexId v = 0; v < n; ++v) {
    const auto first = static_cast<std::int64_t>(row_start[static_cast<std::size_t>(v)]);
    const auto blocks = static_cast<std::int64_t>(row_start[static_cast<std::size_t>(v) + 1]) - first;
    for (int i = 0; i < 3; ++i) outer[3 * v + i] = static_cast<SparseMatrix::StorageIndex>(9 * first + 3 * i * blocks);
  }
  outer[3 * n] = static_cast<SparseMatrix::StorageIndex>(entries);

  tbb::parallel_for(tbb::blocked_range<VertexId>(0, n), [&](const tbb::blocked_range<VertexId>& range) {
    for (VertexId v = range.begin(); v != range.end(); ++v) {
      const auto first = static_cast<std::size_t>(row_start[static_cast<std::size_t>(v)]);
      const auto blocks = static_cast<std::size_t>(row_start[static_cast<std::size_t>(v) + 1]) - first;
      const bool keep_values = copied(v);
      for (int i = 0; i < 3; ++i) {
        const auto at = outer[3 * v + i];
        auto* columns = m.innerIndexPtr() + at;
        for (std::size_t k = 0; k < blocks; ++k)
          for (int j = 0; j < 3; ++j) columns[3 * k + static_cast<std::size_t>(j)] = 3 * column[first + k] + j;
        if (keep_values) std::copy_n(previous->valuePtr() + previous->outerIndexPtr()[3 * v + i], 3 * blocks, m.valuePtr() + at);
        else std::fill_n(m.valuePtr() + at, 3 * blocks, 0.0);
      }
    }
  });
  return m;
}

/// The block pattern: rows of unaffected vertices copied from `previous` when given.
void build_block_pattern(const LinkedVolume& volume, const BlockSparseMatrix<double>* previous, const std::vector<std::uint8_t>* affected,
                         std::vector<std::int32_t>& row_start, std::vector<std::int32_t>& column) {
  const auto copied = [&](VertexId v) {
    return previous != nullptr && (*affected)[static_cast<std::size_t>(v)] == 0 && v < previous->block_rows();
  };
  const auto width = [&](VertexId v) {
    return previous->row_start[static_cast<std::size_t>(v) + 1] - previous->row_start[static_cast<std::size_t>(v)];
  };
  const auto column_of = [&](VertexId v, std::int32_t k) {
    return previous->column[static_cast<std::size_t>(previous->row_start[static_cast<std::size_t>(v)] + k)];
  };
  build_block_rows(volume, copied, width, column_of, row_start, column);
}

}  // namespace

BlockSparseMatrix<double> make_vertex_block_csr(const LinkedVolume& volume) {
  BlockSparseMatrix<double> m;
  build_block_pattern(volume, nullptr, nullptr, m.row_start, m.column);
  m.values.assign(9 * m.column.size(), 0.0);
  return m;
}

void repattern_vertex_block_csr(const LinkedVolume& volume, BlockSparseMatrix<double>& matrix, const std::vector<std::uint8_t>& affected) {
  std::vector<std::int32_t> row_start, column;
  build_block_pattern(volume, &matrix, &affected, row_start, column);
  matrix.row_start.swap(row_start);
  matrix.column.swap(column);
  // The value buffer is kept: fresh memory costs a page fault per 4 KB page (100 MB at 44k cells:
  // ~200 ms on this machine's virtualized memory), so it grows with headroom for later cuts.
  const std::size_t values = 9 * matrix.column.size();
  if (values > matrix.values.capacity()) matrix.values.reserve(values + values / 16);
  matrix.values.resize(values);
}

SparseMatrix make_vertex_block_pattern(const LinkedVolume& volume) { return build_pattern(volume, nullptr, nullptr); }

SparseMatrix rebuild_vertex_block_pattern(const LinkedVolume& volume, const SparseMatrix& previous,
                                          const std::vector<std::uint8_t>& affected) {
  return build_pattern(volume, &previous, &affected);
}

std::vector<std::uint8_t> vertices_affected_by_cut(const LinkedVolume& volume, const CutReport& report) {
  std::vector<std::uint8_t> affected(static_cast<std::size_t>(volume.vertex_count()), 0);
  for (const CellId c : report.touched_cells)
    for (const VertexId v : volume.cell_vertices(c)) affected[static_cast<std::size_t>(v)] = 1;
  for (const VertexSplit& split : report.splits) {
    affected[static_cast<std::size_t>(split.original)] = 1;
    for (const VertexId v : split.created) affected[static_cast<std::size_t>(v)] = 1;
  }
  return affected;
}

VertexBlockGather make_vertex_block_gather(const LinkedVolume& volume, const BlockSparseMatrix<double>& matrix) {
  const auto& vertex_cells = volume.vertex_cells();
  VertexBlockGather g;
  g.first_slot.assign(vertex_cells.size() + 1, 0);
  for (std::size_t v = 0; v < vertex_cells.size(); ++v)
    g.first_slot[v + 1] = g.first_slot[v] + static_cast<std::int64_t>(vertex_cells[v].size());
  const auto slots = static_cast<std::size_t>(g.first_slot.back());
  g.corner.resize(slots);
  g.block.resize(8 * slots);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertex_cells.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t v = r.begin(); v != r.end(); ++v) {
      const auto first = matrix.column.begin() + matrix.row_start[v];
      const auto last = matrix.column.begin() + matrix.row_start[v + 1];
      for (std::size_t t = 0; t < vertex_cells[v].size(); ++t) {
        const auto slot = static_cast<std::size_t>(g.first_slot[v]) + t;
        const auto& corners = volume.cell_vertices(vertex_cells[v][t]);
        for (int b = 0; b < kCornerCount; ++b) {
          const VertexId w = corners[static_cast<std::size_t>(b)];
          if (w == static_cast<VertexId>(v)) g.corner[slot] = static_cast<std::uint8_t>(b);
          const auto found = std::lower_bound(first, last, static_cast<std::int32_t>(w));
          if (found == last || *found != w)
            throw InputError(fmt::format("vertex block gather: vertex {} shares a cell with {}, but the matrix has no block ({}, {})", v, w, v, w));
          g.block[8 * slot + static_cast<std::size_t>(b)] = static_cast<std::int32_t>(found - matrix.column.begin());
        }
      }
    }
  });
  return g;
}

}  // namespace cleave
