#pragma once
// Chebyshev polynomial smoother with block Jacobi scaling: x is moved towards A^-1 b by a fixed
// polynomial in D^-1 A (D = 3x3 vertex diagonal blocks) that damps the error components whose
// eigenvalues lie in [lambda_max / smoothing_range, lambda_max]. Being a fixed polynomial, the
// same smoother before and after the coarse correction keeps the V-cycle symmetric (a valid CG
// preconditioner); every step is one parallel pass over the matrix (residual and D^-1 fused).
//
//   ChebyshevSmoother s = make_chebyshev_smoother(a, options);   // a: block CSR, float or double
//   s.smooth_from_zero(a, b, x, work);   // x = p(D^-1 A) D^-1 b
//   s.smooth(a, b, x, work);             // x += p(D^-1 A) D^-1 (b - A x)
//
// Smoothing runs on the block CSR copy of a (block_sparse_matrix.hpp), in single precision where
// the multigrid cycle does (half the bytes streamed; the outer double-precision CG absorbs the
// rounding) or in double. lambda_max of D^-1 A is estimated by power iteration (double) and enlarged
// by a safety factor.
#include "cleave/solve/block_jacobi.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/vertex_operator.hpp"

namespace cleave {

struct ChebyshevOptions {
  int degree = 2;                    ///< sparse products per smoothing (from zero: degree - 1)
  double smoothing_range = 8.0;      ///< lambda_max / lower end of the damped interval
  int power_iterations = 12;         ///< for the lambda_max estimate
  /// ... after a cut, from the level's last power-iteration vector (ChebyshevWarmStart): a cut
  /// changes D^-1 A only near it, so the old dominant vector is already close. 12 cold iterations
  /// cost 15-20 ms on the 44k tube's fine level, at every step after a cut segment.
  int warm_power_iterations = 4;
  double lambda_safety_factor = 1.15;  ///< multiplies the power-iteration estimate
};

template <typename Scalar>
struct ChebyshevWork {
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> d, z;
};

class ChebyshevSmoother {
 public:
  std::vector<Mat3> inverse_diagonal;          ///< per vertex: D^-1 block
  std::vector<Mat3f> inverse_diagonal_single;  ///< the same in single precision
  double lambda_max = 1;  ///< upper end of the damped interval (safety factor included)
  Eigen::VectorXd lambda_vector;  ///< the power iteration's last vector (unit length): a warm start after cuts
  ChebyshevOptions options;

  /// New D^-1 (new values of the same matrix); lambda_max is kept.
  void set_inverse_diagonal(std::vector<Mat3> inverse);
  /// D^-1 in the given precision.
  template <typename Scalar>
  const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_blocks() const;

  template <typename Scalar>
  void smooth_from_zero(const BlockSparseMatrix<Scalar>& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                        Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const;
  template <typename Scalar>
  void smooth(const BlockSparseMatrix<Scalar>& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
              Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const;
  /// The same with A applied without its matrix (the dynamic step's fine level).
  template <typename Scalar>
  void smooth_from_zero(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                        Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const;
  template <typename Scalar>
  void smooth(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
              Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const;

 private:
  enum class Start { from_zero, from_x };
  template <typename Matrix, typename Scalar>
  void iterate(const Matrix& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
               ChebyshevWork<Scalar>& work, Start start) const;
};

/// The smoother of a level before cuts divided its vertices (vertex n + i of the new level is a
/// copy of origin_of_new[i]; no copies: the same vertices, a rebuild for new values): the new
/// smoother's lambda_max estimate starts from the old one's power-iteration vector (copies take
/// their origin's entries) and runs warm_power_iterations;
/// it is kept at least at the old estimate, so too few iterations cannot lower it. Without a
/// vector of the old size (a smoother made before it kept one), the estimate starts cold.
struct ChebyshevWarmStart {
  const ChebyshevSmoother* before = nullptr;
  const std::vector<VertexId>* origin_of_new = nullptr;
};

/// D^-1 and the lambda_max estimate from `a` (power iteration in a's precision).
template <typename Scalar>
ChebyshevSmoother make_chebyshev_smoother(const BlockSparseMatrix<Scalar>& a, const ChebyshevOptions& options = {},
                                          const ChebyshevWarmStart& warm = {});
/// The same for A applied without its matrix, with its D^-1 given; power iteration in Scalar.
template <typename Scalar>
ChebyshevSmoother make_chebyshev_smoother(const VertexOperator& a, std::vector<Mat3> inverse_diagonal, const ChebyshevOptions& options,
                                          const ChebyshevWarmStart& warm = {});

}  // namespace cleave
