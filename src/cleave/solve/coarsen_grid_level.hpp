#pragma once
// One coarsening step of the cut-aware multigrid hierarchy (after Dick, Georgii & Westermann
// 2011) and the prolongation that goes with it.
//
//   Coarsening next = coarsen_grid_level(fine);
//   next.coarse             // the coarser GridLevel
//   next.prolongation       // fine vertex values from coarse vertex values
//
// Coarse cells: the fine cells of each 2x2x2 block (parent voxel = voxel / 2) are grouped by
// the uncut links inside the block; every group becomes its own coarse cell (a replica of the
// parent voxel), so pieces a cut separated inside a block stay apart. Coarse links: two coarse
// cells are linked across face f when one of their fine cells is linked to the other's across f.
// Coarse vertices: as in the linked volume, a coarse grid corner is one vertex for the coarse
// cells around it that are connected through coarse links across faces containing that corner,
// and split otherwise. Cells that share no fine link therefore share no coarse vertex, so
// disconnected parts stay disconnected on every level.
// Prolongation: each fine vertex takes the trilinear weights of its position inside the coarse
// cell of one fine cell that uses it (weights 1, 1/2, 1/4, 1/8; zero weights are dropped).
#include <vector>

#include "cleave/solve/grid_level.hpp"

namespace cleave {

/// Sparse fine x coarse interpolation on vertices (one scalar weight per pair; the same for
/// the x, y and z dof), stored by fine rows and, transposed, by coarse rows for restriction.
struct Prolongation {
  struct Entry {
    VertexId vertex = kNone;  ///< coarse vertex (in `by_fine`) or fine vertex (in `by_coarse`)
    double weight = 0;
  };
  std::vector<int> fine_start;    ///< fine vertex v's entries: by_fine[fine_start[v] .. fine_start[v+1])
  std::vector<Entry> by_fine;
  std::vector<int> coarse_start;  ///< coarse vertex V's entries: by_coarse[coarse_start[V] .. coarse_start[V+1])
  std::vector<Entry> by_coarse;

  VertexId fine_count() const { return static_cast<VertexId>(fine_start.size()) - 1; }
  VertexId coarse_count() const { return static_cast<VertexId>(coarse_start.size()) - 1; }
};

struct Coarsening {
  GridLevel coarse;
  std::vector<CellId> coarse_cell_of_fine;  ///< per fine cell
  Prolongation prolongation;
};

Coarsening coarsen_grid_level(const GridLevel& fine);

}  // namespace cleave
