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

/// Shared by the fresh and the incremental pattern: `previous` is null for a fresh one.
SparseMatrix build_pattern(const LinkedVolume& volume, const SparseMatrix* previous,
                           const std::vector<std::uint8_t>* affected) {
  const VertexId n = volume.vertex_count();
  volume.vertex_cells();  // build the lazy cache before the parallel loops
  const auto copied = [&](VertexId v) {
    return previous != nullptr && (*affected)[static_cast<std::size_t>(v)] == 0 && 3 * v < previous->rows();
  };
  std::vector<std::int64_t> row_width(static_cast<std::size_t>(n));
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, n), [&](const tbb::blocked_range<VertexId>& range) {
    std::vector<VertexId> neighbours;
    for (VertexId v = range.begin(); v != range.end(); ++v) {
      if (copied(v)) {
        row_width[static_cast<std::size_t>(v)] = previous->outerIndexPtr()[3 * v + 1] - previous->outerIndexPtr()[3 * v];
      } else {
        vertex_neighbours(volume, v, neighbours);
        row_width[static_cast<std::size_t>(v)] = 3 * static_cast<std::int64_t>(neighbours.size());
      }
    }
  });
  SparseMatrix m(3 * static_cast<Eigen::Index>(n), 3 * static_cast<Eigen::Index>(n));
  std::int64_t nnz = 0;
  for (VertexId v = 0; v < n; ++v) nnz += 3 * row_width[static_cast<std::size_t>(v)];
  m.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  auto* outer = m.outerIndexPtr();
  std::int64_t at = 0;
  for (VertexId v = 0; v < n; ++v)
    for (int i = 0; i < 3; ++i) {
      outer[3 * v + i] = static_cast<SparseMatrix::StorageIndex>(at);
      at += row_width[static_cast<std::size_t>(v)];
    }
  outer[3 * n] = static_cast<SparseMatrix::StorageIndex>(at);

  tbb::parallel_for(tbb::blocked_range<VertexId>(0, n), [&](const tbb::blocked_range<VertexId>& range) {
    std::vector<VertexId> neighbours;
    for (VertexId v = range.begin(); v != range.end(); ++v) {
      const auto width = row_width[static_cast<std::size_t>(v)];
      if (copied(v)) {
        for (int i = 0; i < 3; ++i) {
          const auto from = previous->outerIndexPtr()[3 * v + i];
          std::copy_n(previous->innerIndexPtr() + from, width, m.innerIndexPtr() + outer[3 * v + i]);
          std::copy_n(previous->valuePtr() + from, width, m.valuePtr() + outer[3 * v + i]);
        }
        continue;
      }
      vertex_neighbours(volume, v, neighbours);
      for (int i = 0; i < 3; ++i) {
        auto* columns = m.innerIndexPtr() + outer[3 * v + i];
        for (std::size_t k = 0; k < neighbours.size(); ++k)
          for (int j = 0; j < 3; ++j) columns[3 * k + static_cast<std::size_t>(j)] = 3 * neighbours[k] + j;
        std::fill_n(m.valuePtr() + outer[3 * v + i], width, 0.0);
      }
    }
  });
  return m;
}

/// The block rows and columns of the current topology (values untouched): rows of unaffected
/// vertices copied from `previous` when given. Shared by the fresh and the incremental pattern.
void build_block_pattern(const LinkedVolume& volume, const BlockSparseMatrix<double>* previous, const std::vector<std::uint8_t>* affected,
                         std::vector<std::int32_t>& row_start, std::vector<std::int32_t>& column) {
  const VertexId n = volume.vertex_count();
  volume.vertex_cells();  // build the lazy cache before the parallel loops
  const auto copied = [&](VertexId v) {
    return previous != nullptr && (*affected)[static_cast<std::size_t>(v)] == 0 && v < previous->block_rows();
  };
  row_start.assign(static_cast<std::size_t>(n) + 1, 0);
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, n), [&](const tbb::blocked_range<VertexId>& range) {
    std::vector<VertexId> neighbours;
    for (VertexId v = range.begin(); v != range.end(); ++v) {
      const auto row = static_cast<std::size_t>(v);
      if (copied(v)) {
        row_start[row + 1] = previous->row_start[row + 1] - previous->row_start[row];
      } else {
        vertex_neighbours(volume, v, neighbours);
        row_start[row + 1] = static_cast<std::int32_t>(neighbours.size());
      }
    }
  });
  for (std::size_t row = 0; row < static_cast<std::size_t>(n); ++row) row_start[row + 1] += row_start[row];
  column.resize(static_cast<std::size_t>(row_start.back()));
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, n), [&](const tbb::blocked_range<VertexId>& range) {
    std::vector<VertexId> neighbours;
    for (VertexId v = range.begin(); v != range.end(); ++v) {
      const auto row = static_cast<std::size_t>(v);
      auto* columns = column.data() + row_start[row];
      if (copied(v)) {
        const auto from = previous->column.begin() + previous->row_start[row];
        std::copy(from, previous->column.begin() + previous->row_start[row + 1], columns);
        continue;
      }
      vertex_neighbours(volume, v, neighbours);
      std::copy(neighbours.begin(), neighbours.end(), columns);
    }
  });
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
