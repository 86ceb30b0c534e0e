#pragma once
// The global stiffness matrix K of a tissue model on its current (possibly cut) vertices.
//
//   SparseMatrix k = assemble_stiffness(model);              // 3 n_v x 3 n_v, mN/mm
//   CutReport r = model.volume.cut_links(links);
//   update_stiffness_after_cut(model, r, k);                  // equals assemble_stiffness(model)
//
// Dof layout: 3 * vertex + axis (x, y, z); RowMajor; symmetric; the rigid motions of every
// connected component are in its null space (handle them before solving, see solve_static.hpp).
// K^e is computed once per material (ElementTable); assembly gathers rows per vertex in parallel.
#include "cleave/fem/element_table.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

/// Assembles K from K^e of each cell's material (linear elasticity, reference configuration).
SparseMatrix assemble_stiffness(const TissueModel& model);
/// Same with a prepared element table (must belong to `model`).
SparseMatrix assemble_stiffness(const TissueModel& model, const ElementTable& table);

/// After `model.volume.cut_links(...)` returned `report`, brings `stiffness` (assembled before
/// that cut) to the new topology: rows of vertices of touched cells and of new vertices are
/// re-gathered, all other rows are copied. Call once per cut, in order.
void update_stiffness_after_cut(const TissueModel& model, const CutReport& report, SparseMatrix& stiffness);

}  // namespace cleave
