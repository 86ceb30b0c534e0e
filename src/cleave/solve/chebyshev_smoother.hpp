#pragma once
// Chebyshev polynomial smoother with block Jacobi scaling: x is moved towards A^-1 b by a fixed
// polynomial in D^-1 A (D = 3x3 vertex diagonal blocks) that damps the error components whose
// eigenvalues lie in [lambda_max / smoothing_range, lambda_max]. Being a fixed polynomial, the
// same smoother before and after the coarse correction keeps the V-cycle symmetric (a valid CG
// preconditioner); every step is one parallel sparse product.
//
//   ChebyshevSmoother s = make_chebyshev_smoother(a, options);
//   s.smooth_from_zero(a, b, x, work);   // x = p(D^-1 A) D^-1 b
//   s.smooth(a, b, x, work);             // x += p(D^-1 A) D^-1 (b - A x)
//
// lambda_max of D^-1 A is estimated by power iteration and enlarged by a safety factor.
#include "cleave/solve/block_jacobi.hpp"

namespace cleave {

struct ChebyshevOptions {
  int degree = 2;                    ///< sparse products per smoothing (from zero: degree - 1)
  double smoothing_range = 8.0;      ///< lambda_max / lower end of the damped interval
  int power_iterations = 12;         ///< for the lambda_max estimate
  double lambda_safety_factor = 1.15;  ///< multiplies the power-iteration estimate
};

struct ChebyshevWork {
  Vector r, d, z;
};

class ChebyshevSmoother {
 public:
  BlockJacobi diagonal;
  double lambda_max = 1;  ///< upper end of the damped interval (safety factor included)
  ChebyshevOptions options;

  void smooth_from_zero(const SparseMatrix& a, const Vector& b, Vector& x, ChebyshevWork& work) const;
  void smooth(const SparseMatrix& a, const Vector& b, Vector& x, ChebyshevWork& work) const;

 private:
  enum class Start { from_zero, from_x };
  void iterate(const SparseMatrix& a, const Vector& b, Vector& x, ChebyshevWork& work, Start start) const;
};

ChebyshevSmoother make_chebyshev_smoother(const SparseMatrix& a, const ChebyshevOptions& options = {});

}  // namespace cleave
