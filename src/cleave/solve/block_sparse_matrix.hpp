#pragma once
// Block CSR: a sparse matrix on vertex dofs (3 per vertex) stored as dense 3x3 blocks, one block
// row per vertex, values of a block contiguous (row-major) and one column index per block, not
// per value. A product streams 9 values + 1 index per block (40 bytes in float, 76 in double)
// instead of 9 x (value + index) of scalar CSR (108 bytes): the multigrid's products are bound
// by memory bandwidth, so this is what their time is made of.
//
//   BlockSparseMatrix<float> a = to_block_sparse<float>(csr);   // pattern + values
//   refresh_block_values(csr, a);                               // same pattern, new values
//   multiply(a, x, y);  residual(a, b, x, r);                    // y = A x, r = b - A x
//   jacobi_residual(a, inverse_diagonal, b, x, z);                // z = D^-1 (b - A x)
//
// Input CSR: 3 n x 3 n (compressed RowMajor); a block is stored when any of its 9 entries is
// stored in the CSR (missing ones are zero). Products run in parallel over block rows (TBB).
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cleave/solve/linear_solver.hpp"

namespace cleave {

template <typename Scalar>
struct BlockSparseMatrix {
  using VectorType = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  std::vector<std::int32_t> row_start{0};  ///< per block row and one past the last: first block
  std::vector<std::int32_t> column;        ///< per block: block column (vertex)
  std::vector<Scalar> values;              ///< per block: 9 values, row-major

  Eigen::Index block_rows() const { return static_cast<Eigen::Index>(row_start.size()) - 1; }
  Eigen::Index rows() const { return 3 * block_rows(); }
  std::size_t blocks() const { return column.size(); }
};

using Mat3f = Eigen::Matrix3f;

template <typename Scalar>
BlockSparseMatrix<Scalar> to_block_sparse(const SparseMatrix& a);

/// Overwrites the values of `b` from `a`, whose pattern is the one `b` was made from.
template <typename Scalar>
void refresh_block_values(const SparseMatrix& a, BlockSparseMatrix<Scalar>& b);

/// The inverse of refresh_block_values: writes b's values into a, whose pattern b was built from
/// (to_block_sparse(a)); entries of b outside a's pattern are not written.
void copy_block_values(const BlockSparseMatrix<double>& b, SparseMatrix& a);

/// Scalar CSR (compressed RowMajor) with every entry of every stored block, zeros included: the
/// multigrid's coarsest factorization when the fine level is the only one.
SparseMatrix to_scalar_sparse(const BlockSparseMatrix<double>& b);

template <typename Scalar>
void multiply(const BlockSparseMatrix<Scalar>& a, const typename BlockSparseMatrix<Scalar>::VectorType& x,
              typename BlockSparseMatrix<Scalar>::VectorType& y);

template <typename Scalar>
void residual(const BlockSparseMatrix<Scalar>& a, const typename BlockSparseMatrix<Scalar>::VectorType& b,
              const typename BlockSparseMatrix<Scalar>::VectorType& x, typename BlockSparseMatrix<Scalar>::VectorType& r);

/// z = D^-1 (b - A x) in one pass, D^-1 given per vertex (block Jacobi).
template <typename Scalar>
void jacobi_residual(const BlockSparseMatrix<Scalar>& a, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                     const typename BlockSparseMatrix<Scalar>::VectorType& b, const typename BlockSparseMatrix<Scalar>::VectorType& x,
                     typename BlockSparseMatrix<Scalar>::VectorType& z);

}  // namespace cleave
