#pragma once
// The discrete Laplacian over the cells of a linked volume (paper section 6.2):
//   (L phi)(i) = sum over linked face neighbours j of (phi(j) - phi(i)) / |N(i)|,
// i.e. L(i, i) = -1 and L(i, j) = 1 / |N(i)| for the |N(i)| neighbours across uncut links.
// A cell without any linked neighbour keeps L(i, i) = -1 (its value is pulled to zero).
//
//   SparseMatrix l = cell_laplacian(volume);   // n_c x n_c, dimensionless, RowMajor
#include <vector>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

SparseMatrix cell_laplacian(const LinkedVolume& volume);

/// Per cell: true when no cell of its connected piece (uncut links) is in `constrained_cells`.
/// The interpolations pin such pieces to zero instead of leaving their system singular.
std::vector<bool> cells_of_unconstrained_pieces(const LinkedVolume& volume, const std::vector<CellId>& constrained_cells);

}  // namespace cleave
