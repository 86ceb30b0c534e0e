#pragma once
// The coarse operator of a multigrid level by the Galerkin product A_c = P^T A P, where P is the
// vertex prolongation applied to each of the x, y, z dofs and fixed (Dirichlet) fine dofs are left
// out of P, so the coarse problem stays symmetric positive definite and never moves a fixed dof.
//
//   SparseMatrix ac = galerkin_operator(a, fixed, prolongation);
//
// Inputs: a (3 n_f x 3 n_f, compressed RowMajor, symmetric); fixed (3 n_f, 1 = fixed dof, whose
// row and column in `a` are identity); prolongation (n_f fine x n_c coarse vertices).
// Output: 3 n_c x 3 n_c, RowMajor, 3x3 blocks per coupled coarse vertex pair. A coarse dof
// that no free fine dof depends on would have an empty row: it gets 1 on its diagonal (an
// identity row, i.e. treated as fixed on the coarse level). Computed in parallel over vertices.
#include <cstdint>
#include <vector>

#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/coarsen_grid_level.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

SparseMatrix galerkin_operator(const SparseMatrix& a, const std::vector<std::uint8_t>& fixed, const Prolongation& prolongation);
/// The same with `a` given as block CSR (block_sparse_matrix.hpp; the multigrid's fine level has
/// that copy already: no second one of ~100 MB at 44k cells). InputError when the sizes of `a`,
/// `fixed` and the prolongation do not fit together.
SparseMatrix galerkin_operator(const BlockSparseMatrix<double>& a, const std::vector<std::uint8_t>& fixed,
                               const Prolongation& prolongation);

/// Dofs whose row in `a` is an identity row (no off-diagonal entry other than zero): fixed dofs.
std::vector<std::uint8_t> identity_rows(const SparseMatrix& a);
/// The same for `a` as block CSR: row 3 v + i is an identity row when entry (i, i) of block (v, v)
/// is not zero and every other entry of row i of block row v's blocks is zero.
std::vector<std::uint8_t> identity_rows(const BlockSparseMatrix<double>& a);

}  // namespace cleave
