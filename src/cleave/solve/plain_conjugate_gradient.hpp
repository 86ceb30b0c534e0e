#pragma once
// The paper's reference solver: plain conjugate gradients on an SPD system, one thread, no
// preconditioner, from the x given. Kept apart from the preconditioned CG (conjugate_gradient.hpp)
// because it is the peer the benchmarks and the `paper-cg` design path re-run as published.
#include <Eigen/Core>
#include <cmath>

namespace cleave {

struct PlainCgOutcome {
  int iterations = 0;
  double relative_residual = 0;  ///< ||b - A x|| / ||b|| at exit (0 when b = 0)
};

/// Iterates until ||r|| / ||b|| <= relative_tolerance or max_iterations; x holds the start on
/// entry and the result on exit (set to zero when b = 0). Works for any Eigen sparse or dense
/// matrix type; the caller decides what a miss of the tolerance means.
template <typename Matrix>
PlainCgOutcome plain_conjugate_gradient(const Matrix& a, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                        double relative_tolerance, int max_iterations) {
  PlainCgOutcome out;
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    x.setZero();
    return out;
  }
  Eigen::VectorXd r = b - a * x;
  Eigen::VectorXd p = r;
  Eigen::VectorXd ap(x.size());
  double rr = r.squaredNorm();
  out.relative_residual = std::sqrt(rr) / b_norm;
  while (out.relative_residual > relative_tolerance && out.iterations < max_iterations) {
    ap.noalias() = a * p;
    const double alpha = rr / p.dot(ap);
    x += alpha * p;
    r -= alpha * ap;
    const double rr_next = r.squaredNorm();
    p = r + (rr_next / rr) * p;
    rr = rr_next;
    ++out.iterations;
    out.relative_residual = std::sqrt(rr) / b_norm;
  }
  return out;
}

}  // namespace cleave
