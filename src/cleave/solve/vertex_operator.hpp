#pragma once
// A symmetric operator on vertex dofs (3 per vertex) that is applied without storing its matrix:
// the dynamic step's corotated system, computed cell by cell from the cells' rotations and one
// element matrix per material (fem/corotated_system_operator.hpp). The CG and the multigrid's fine
// level take it where they would multiply with the assembled block CSR matrix, which then need
// not be assembled for the step: a pass reads the cells' rotations (36 B per cell in float)
// instead of the matrix's 3x3 blocks (1.3 M blocks, 53 MB in float at 44k cells).
//
//   multiply(op, x, y);                 // y = A x       (float or double)
//   residual(op, b, x, r);              // r = b - A x
//   jacobi_residual(op, d_inv, b, x, z);  // z = D^-1 (b - A x)
//   op.chebyshev_step(d_inv, b, x, d, c_d, c_z, work);  // d = c_d d + c_z D^-1 (b - A x); x += d
//
// Fixed dofs follow linear_solver.hpp: identity rows and zero columns.
#include <cstdint>
#include <vector>

#include "cleave/core/types.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"

namespace cleave {

class VertexOperator {
 public:
  virtual ~VertexOperator() = default;
  virtual Eigen::Index rows() const = 0;
  /// y = A x (y is resized); one product at a time per object (it may use work buffers).
  virtual void multiply(const Eigen::VectorXf& x, Eigen::VectorXf& y) const = 0;
  virtual void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const = 0;
  /// Per vertex: the inverse of A's 3x3 diagonal block (the identity where it is singular, as
  /// inverse_diagonal_blocks of a block CSR matrix).
  virtual std::vector<Mat3> inverse_diagonal_blocks() const = 0;
  /// A assembled (compressed, RowMajor; fixed dofs eliminated): for a solver that must rebuild
  /// from the matrix.
  virtual SparseMatrix assembled_matrix() const = 0;
  /// Per dof: 1 where A has an identity row (a fixed dof).
  virtual const std::vector<std::uint8_t>& fixed_dofs() const = 0;
  /// r = b - A x (r is resized, and must not be x or b). By default a product, then a pass; an
  /// operator that sums its products per vertex may do both at once.
  virtual void residual(const Eigen::VectorXf& b, const Eigen::VectorXf& x, Eigen::VectorXf& r) const;
  virtual void residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const;
  /// z = D^-1 (b - A x), D^-1 per vertex `inverse_diagonal` (a smoothing step; z is resized, and
  /// must not be x or b). By default a product, then a pass over the vertices; an operator that
  /// sums its products per vertex may do both at once.
  virtual void jacobi_residual(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b, const Eigen::VectorXf& x,
                               Eigen::VectorXf& z) const;
  virtual void jacobi_residual(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                               Eigen::VectorXd& z) const;
  /// A Chebyshev smoothing step: d = c_d d + c_z D^-1 (b - A x), then x += d (d and x of the
  /// operator's size; `work` may be used for D^-1 (b - A x)). By default jacobi_residual, then a
  /// pass; an operator that sums its products per vertex may do both at once.
  virtual void chebyshev_step(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b, Eigen::VectorXf& x,
                              Eigen::VectorXf& d, float c_d, float c_z, Eigen::VectorXf& work) const;
  virtual void chebyshev_step(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                              Eigen::VectorXd& d, double c_d, double c_z, Eigen::VectorXd& work) const;
};

template <typename Scalar>
void multiply(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& y) {
  a.multiply(x, y);
}

template <typename Scalar>
void residual(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
              const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& r);

template <typename Scalar>
void jacobi_residual(const VertexOperator& a, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                     const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                     Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z);

}  // namespace cleave
