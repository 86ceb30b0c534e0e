#pragma once
// Sparse matrices on the vertex degrees of freedom of a linked volume (dof 3 * vertex + axis),
// made of 3x3 blocks: row block v holds one 3x3 block per vertex w that shares a cell with v.
// Rows are built per vertex by gathering from the cells around it, so assembly runs in parallel
// over vertices without write conflicts, and a cut re-gathers only the rows it affects.
//
// The pattern follows the current vertices of the volume (split vertices are separate rows);
// the diagonal block of every vertex is always present.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

/// Sorted distinct vertices sharing a cell with v (v included), written to `out`.
void vertex_neighbours(const LinkedVolume& volume, VertexId v, std::vector<VertexId>& out);

/// All-zero matrix (3 n_v x 3 n_v) with the block pattern of the volume's current topology.
SparseMatrix make_vertex_block_pattern(const LinkedVolume& volume);

/// Pattern of the current topology where the rows of vertices with affected[v] == 0 are copied,
/// columns and values, from `previous` (built before a cut; those rows must be unchanged by it)
/// and the rows of affected vertices are zero. `affected` has one entry per current vertex.
SparseMatrix rebuild_vertex_block_pattern(const LinkedVolume& volume, const SparseMatrix& previous,
                                          const std::vector<std::uint8_t>& affected);

/// The same pattern as block CSR (one 3x3 block per vertex pair sharing a cell), values zero:
/// what the dynamic step assembles into. No scalar CSR is made on the way.
BlockSparseMatrix<double> make_vertex_block_csr(const LinkedVolume& volume);

/// After a cut: gives `matrix` (block CSR with the block pattern before it) the pattern of the
/// current topology, copying the block columns of the rows of vertices with affected[v] == 0
/// (unchanged by the cut) and finding the others afresh. The values are left unspecified (the
/// caller assembles every row): their buffer is reused, not allocated anew. On the 44k tube this
/// takes ~20 ms where the scalar rebuild and its conversion to blocks took ~250 ms.
void repattern_vertex_block_csr(const LinkedVolume& volume, BlockSparseMatrix<double>& matrix, const std::vector<std::uint8_t>& affected);

/// Vertices whose rows a cut changes: every vertex of a touched cell (new vertices included).
std::vector<std::uint8_t> vertices_affected_by_cut(const LinkedVolume& volume, const CutReport& report);

/// Overwrites the 3 rows of vertex v with the sum over cells c around v (v = corner a of c) and
/// corners b of block(c, a, b) (a Mat3) at block column corner_vertex(c, b).
/// `matrix` must hold the pattern of the current topology for these rows. Call
/// volume.vertex_cells() once before using this from several threads.
template <typename BlockFn>
void gather_vertex_rows(const LinkedVolume& volume, VertexId v, const BlockFn& block, SparseMatrix& matrix) {
  const auto* outer = matrix.outerIndexPtr();
  const auto* inner = matrix.innerIndexPtr();
  double* values = matrix.valuePtr();
  const auto row0 = static_cast<std::ptrdiff_t>(outer[3 * v]);
  const auto width = static_cast<std::ptrdiff_t>(outer[3 * v + 1]) - row0;  // 3 * neighbours
  std::ptrdiff_t start[3];
  for (int i = 0; i < 3; ++i) {
    start[i] = outer[3 * v + i];
    std::fill(values + start[i], values + start[i] + width, 0.0);
  }
  for (const CellId c : volume.vertex_cells()[static_cast<std::size_t>(v)]) {
    const auto& corners = volume.cell_vertices(c);
    int a = 0;
    while (corners[static_cast<std::size_t>(a)] != v) ++a;
    for (int b = 0; b < kCornerCount; ++b) {
      const int column = 3 * corners[static_cast<std::size_t>(b)];
      const auto* first = inner + row0;
      const auto* found = std::lower_bound(first, first + width, column);
      const std::ptrdiff_t offset = found - first;
      const Mat3 m = block(c, a, b);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) values[start[i] + offset + j] += m(i, j);
    }
  }
}

/// Where the gather into block CSR writes: for vertex v and the t-th cell around it
/// (volume.vertex_cells()[v][t]), v's corner in that cell and, per corner b of the cell, the
/// block of row v at column corner_vertex(b). Made once per topology, it spares every assembly
/// the search of those blocks in the row.
struct VertexBlockGather {
  std::vector<std::int64_t> first_slot;  ///< per vertex and one past the last: first (v, t) slot
  std::vector<std::uint8_t> corner;      ///< per slot: v's corner (0..7) in the cell
  std::vector<std::int32_t> block;       ///< per slot, 8 each: the block index for corner b
};

/// The gather table of `matrix` (block CSR with the block pattern of the volume's current topology).
VertexBlockGather make_vertex_block_gather(const LinkedVolume& volume, const BlockSparseMatrix<double>& matrix);

/// The same as gather_vertex_rows into block CSR: overwrites block row v of `matrix` (the matrix
/// `gather` was made for) with the sum over the cells c around v and corners b of block(c, a, b).
template <typename BlockFn>
void gather_vertex_block_row(const LinkedVolume& volume, VertexId v, const VertexBlockGather& gather, const BlockFn& block,
                             BlockSparseMatrix<double>& matrix) {
  const auto row = static_cast<std::size_t>(v);
  double* values = matrix.values.data();
  std::fill(values + 9 * static_cast<std::size_t>(matrix.row_start[row]), values + 9 * static_cast<std::size_t>(matrix.row_start[row + 1]), 0.0);
  const std::vector<CellId>& cells = volume.vertex_cells()[row];
  for (std::size_t t = 0; t < cells.size(); ++t) {
    const auto slot = static_cast<std::size_t>(gather.first_slot[row]) + t;
    const int a = gather.corner[slot];
    for (int b = 0; b < kCornerCount; ++b) {
      const Mat3 m = block(cells[t], a, b);
      double* target = values + 9 * static_cast<std::size_t>(gather.block[8 * slot + static_cast<std::size_t>(b)]);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) target[3 * i + j] += m(i, j);
    }
  }
}

}  // namespace cleave
