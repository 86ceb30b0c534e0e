#pragma once
// Chebyshev polynomial smoother with block Jacobi scaling: x is moved towards A^-1 b by a fixed
// polynomial in D^-1 A (D = 3x3 vertex diagonal blocks) that damps the error components whose
// eigenvalues lie in [lambda_max / smoothing_range, lambda_max]. Being a fixed polynomial, the
// same smoother before and after the coarse correction keeps the V-cycle symmetric (a valid CG
// preconditioner); every step is one parallel pass over the matrix (residual and D^-1 fused).
//
//   ChebyshevSmoother s = make_chebyshev_smoother(a, options);   // a: double CSR (estimate)
//   s.smooth_from_zero(blocks, b, x, work);   // x = p(D^-1 A) D^-1 b       (blocks: a in float)
//   s.smooth(blocks, b, x, work);             // x += p(D^-1 A) D^-1 (b - A x)
//
// Smoothing runs in single precision on the block CSR copy of a (block_sparse_matrix.hpp): it is
// part of a preconditioner, whose rounding the outer double-precision CG absorbs, and it halves
// the bytes streamed. lambda_max of D^-1 A is estimated by power iteration (double) and enlarged
// by a safety factor.
#include "cleave/solve/block_jacobi.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"

namespace cleave {

struct ChebyshevOptions {
  int degree = 2;                    ///< sparse products per smoothing (from zero: degree - 1)
  double smoothing_range = 8.0;      ///< lambda_max / lower end of the damped interval
  int power_iterations = 12;         ///< for the lambda_max estimate
  double lambda_safety_factor = 1.15;  ///< multiplies the power-iteration estimate
};

struct ChebyshevWork {
  Eigen::VectorXf d, z;
};

class ChebyshevSmoother {
 public:
  std::vector<Mat3f> inverse_diagonal;  ///< per vertex: D^-1 block (single precision)
  double lambda_max = 1;  ///< upper end of the damped interval (safety factor included)
  ChebyshevOptions options;

  void smooth_from_zero(const BlockSparseMatrix<float>& a, const Eigen::VectorXf& b, Eigen::VectorXf& x, ChebyshevWork& work) const;
  void smooth(const BlockSparseMatrix<float>& a, const Eigen::VectorXf& b, Eigen::VectorXf& x, ChebyshevWork& work) const;

 private:
  enum class Start { from_zero, from_x };
  void iterate(const BlockSparseMatrix<float>& a, const Eigen::VectorXf& b, Eigen::VectorXf& x, ChebyshevWork& work,
               Start start) const;
};

ChebyshevSmoother make_chebyshev_smoother(const SparseMatrix& a, const ChebyshevOptions& options = {});

}  // namespace cleave
