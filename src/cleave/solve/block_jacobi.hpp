#pragma once
// Block Jacobi on vertex dofs: the inverse of each vertex's 3x3 diagonal block of A (dofs
// 3 v .. 3 v + 2). Used as the CG preconditioner of the fallback path and inside the multigrid
// smoother, where it keeps the x, y, z coupling of a vertex that point Jacobi would lose.
//
//   BlockJacobi d = block_jacobi(a);
//   d.apply(r, z);                                     // z = D^-1 r
//
// Input: a (3 n x 3 n, compressed RowMajor, symmetric). A block that is not invertible (a row
// without stiffness, e.g. a vertex of no cell) is replaced by the identity so that no NaN arises.
// Throws InputError when the size is not a multiple of 3.
#include <vector>

#include "cleave/core/types.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/conjugate_gradient.hpp"

namespace cleave {

class BlockJacobi final : public Preconditioner {
 public:
  std::vector<Mat3> inverse_blocks;  ///< per vertex
  void apply(const Vector& r, Vector& z) const override;
};

BlockJacobi block_jacobi(const SparseMatrix& a);

/// The inverse of a vertex block, or the identity when it is singular (|det| below 1e-14 of its
/// norm cubed): no NaN ever.
Mat3 inverse_or_identity(const Mat3& block);

/// The same inverse blocks (in double), from a block CSR matrix (float or double).
template <typename Scalar>
std::vector<Mat3> inverse_diagonal_blocks(const BlockSparseMatrix<Scalar>& a);

}  // namespace cleave
