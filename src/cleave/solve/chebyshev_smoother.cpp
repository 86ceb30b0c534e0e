#include "cleave/solve/chebyshev_smoother.hpp"

#include <cmath>

#include "cleave/solve/sparse_multiply.hpp"

namespace cleave {

ChebyshevSmoother make_chebyshev_smoother(const SparseMatrix& a, const ChebyshevOptions& options) {
  ChebyshevSmoother s;
  s.options = options;
  s.diagonal = block_jacobi(a);
  // Power iteration on D^-1 A from a fixed, non-special start vector (deterministic).
  const Eigen::Index n = a.rows();
  Vector x(n), y(n), z(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = 1.0 + 0.5 * std::sin(0.7 * static_cast<double>(i));
  double estimate = 1;
  for (int k = 0; k < options.power_iterations; ++k) {
    const double norm = x.norm();
    if (!(norm > 0) || !std::isfinite(norm)) break;
    x /= norm;
    multiply(a, x, y);
    s.diagonal.apply(y, z);
    estimate = x.dot(z);  // Rayleigh-like quotient (x normalised)
    x = z;
  }
  const double growth = x.norm();
  if (std::isfinite(growth) && growth > estimate) estimate = growth;
  s.lambda_max = options.lambda_safety_factor * (std::isfinite(estimate) && estimate > 0 ? estimate : 1.0);
  return s;
}

void ChebyshevSmoother::smooth_from_zero(const SparseMatrix& a, const Vector& b, Vector& x, ChebyshevWork& work) const {
  iterate(a, b, x, work, Start::from_zero);
}

void ChebyshevSmoother::smooth(const SparseMatrix& a, const Vector& b, Vector& x, ChebyshevWork& work) const {
  iterate(a, b, x, work, Start::from_x);
}

// Chebyshev iteration on [lower, upper] (Saad, Iterative Methods, algorithm 12.1) with D^-1.
void ChebyshevSmoother::iterate(const SparseMatrix& a, const Vector& b, Vector& x, ChebyshevWork& work,
                                Start start) const {
  const double upper = lambda_max;
  const double lower = lambda_max / options.smoothing_range;
  const double theta = 0.5 * (upper + lower);
  const double delta = 0.5 * (upper - lower);
  const double sigma = theta / delta;
  double rho = 1.0 / sigma;
  if (start == Start::from_zero) {
    work.r = b;
    x.setZero(b.size());
  } else {
    residual(a, b, x, work.r);
  }
  diagonal.apply(work.r, work.z);
  work.d = work.z / theta;
  x += work.d;
  for (int k = 1; k < options.degree; ++k) {
    residual(a, b, x, work.r);
    diagonal.apply(work.r, work.z);
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    work.d = (rho_next * rho) * work.d + (2.0 * rho_next / delta) * work.z;
    x += work.d;
    rho = rho_next;
  }
}

}  // namespace cleave
