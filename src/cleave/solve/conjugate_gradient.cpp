#include "cleave/solve/conjugate_gradient.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/parallel_ranges.hpp"
#include "cleave/solve/sparse_multiply.hpp"

namespace cleave {
namespace {

/// Restarts from the true residual when the recurrence claims convergence but the true residual
/// (rounding drift) does not; more than a couple never help.
constexpr int kMaxRestarts = 2;

enum class CgStop { converged_recurrence, out_of_iterations, breakdown };

/// The iteration's vector work runs on all cores in fixed ranges (parallel_ranges.hpp), summed in
/// a fixed order (deterministic: the same sums, whatever the threads): at 150k dofs each serial
/// pass cost about 0.1 ms, six of them per iteration.

template <typename RangeSum>
double sum_over_ranges(Eigen::Index n, RangeSum&& range_sum) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<Eigen::Index>(0, n, kEntriesPerRange), 0.0,
      [&](const tbb::blocked_range<Eigen::Index>& r, double partial) { return partial + range_sum(r.begin(), r.end() - r.begin()); },
      std::plus<>());
}

double parallel_dot(const Vector& a, const Vector& b) {
  return sum_over_ranges(a.size(), [&](Eigen::Index start, Eigen::Index length) {
    return a.segment(start, length).dot(b.segment(start, length));
  });
}

/// x += alpha p and r -= alpha q in one pass; returns ||r||^2.
double step_along(double alpha, const Vector& p, const Vector& q, Vector& x, Vector& r) {
  return sum_over_ranges(x.size(), [&](Eigen::Index start, Eigen::Index length) {
    x.segment(start, length).noalias() += alpha * p.segment(start, length);
    r.segment(start, length).noalias() -= alpha * q.segment(start, length);
    return r.segment(start, length).squaredNorm();
  });
}

/// p = z + beta p.
void next_direction(const Vector& z, double beta, Vector& p) {
  for_each_range(p.size(), [&](Eigen::Index begin, Eigen::Index end) {
    p.segment(begin, end - begin) = z.segment(begin, end - begin) + beta * p.segment(begin, end - begin);
  });
}

/// q = A p of a CG iteration: in double, or (settings.single_precision_products, operators only)
/// in single precision through the work vectors.
template <typename Matrix>
class IterationProduct {
 public:
  explicit IterationProduct(const SolveSettings&) {}
  void operator()(const Matrix& a, const Vector& p, Vector& q) { multiply(a, p, q); }
};

template <>
class IterationProduct<VertexOperator> {
 public:
  explicit IterationProduct(const SolveSettings& settings) : single_(settings.single_precision_products) {}
  void operator()(const VertexOperator& a, const Vector& p, Vector& q) {
    if (!single_) {
      a.multiply(p, q);
      return;
    }
    cast_in_parallel(p, p_single_);
    a.multiply(p_single_, q_single_);
    cast_in_parallel(q_single_, q);
  }

 private:
  bool single_;
  Eigen::VectorXf p_single_, q_single_;
};

/// Plain PCG from x; `iterations` is increased by the iterations done. When `initial_norm` is not
/// null it receives ||b - A x|| of the start (before any iteration); with `zero_when_better` the
/// start is x = 0 instead when x is farther from the solution in the energy norm (see
/// SolveSettings::zero_start_when_better). `recurrence_norm`: the recurrence's last ||r||.
template <typename Matrix>
CgStop run_pcg(const Matrix& a, const Vector& b, Vector& x, const Preconditioner& preconditioner, IterationProduct<Matrix>& product,
               double& target, double initial_factor, double* initial_norm, bool zero_when_better, int max_iterations,
               int& iterations, double& recurrence_norm) {
  const Eigen::Index n = a.rows();
  Vector r(n), z(n), p(n), q(n);
  residual(a, b, x, r);
  // 1/2 ||x - x*||_A^2 - 1/2 ||x*||_A^2 = 1/2 x^T A x - b^T x = -1/2 x^T (b + r): above zero, the
  // guess is worse than x = 0, whose value it is.
  if (zero_when_better && x.dot(b + r) < 0) {
    x.setZero();
    r = b;
  }
  if (initial_norm != nullptr) {
    *initial_norm = r.norm();
    target = std::max(target, initial_factor * *initial_norm);
  }
  recurrence_norm = r.norm();
  if (recurrence_norm <= target) return CgStop::converged_recurrence;
  preconditioner.apply(r, z);
  p = z;
  double rz = parallel_dot(r, z);
  while (iterations < max_iterations) {
    product(a, p, q);
    const double curvature = parallel_dot(p, q);
    if (!(curvature > 0) || !(rz > 0) || !std::isfinite(curvature) || !std::isfinite(rz)) return CgStop::breakdown;
    const double alpha = rz / curvature;
    ++iterations;
    const double r_norm = std::sqrt(step_along(alpha, p, q, x, r));
    recurrence_norm = r_norm;
    if (!std::isfinite(r_norm)) return CgStop::breakdown;
    if (r_norm <= target) return CgStop::converged_recurrence;
    // Out of iterations, the next direction would never be used: no preconditioner for it (a
    // V-cycle, a fifth of a budgeted dynamic step).
    if (iterations >= max_iterations) break;
    preconditioner.apply(r, z);
    const double rz_next = parallel_dot(r, z);
    next_direction(z, rz_next / rz, p);
    rz = rz_next;
  }
  return CgStop::out_of_iterations;
}

template <typename Matrix>
SolveReport preconditioned_cg_any(const Matrix& a, const Vector& b, Vector& x, const Preconditioner& preconditioner,
                                  const SolveSettings& settings) {
  SolveReport report;
  const Eigen::Index n = a.rows();
  if (x.size() != n || !x.allFinite()) x = Vector::Zero(n);
  const double b_norm = b.norm();
  if (!(b_norm > 0)) {  // zero (or non-finite) load
    x.setZero();
    report.converged = std::isfinite(b_norm);
    return report;
  }
  // The looser of the two rules: relative to b, and relative to the initial guess's residual
  // (which run_pcg measures at its start, the first time).
  double target = settings.relative_tolerance * b_norm;
  const double initial_factor = std::max(settings.initial_residual_tolerance, 0.0);
  double initial_norm = 0;
  const Vector start = x;
  Vector r(n);
  double r_norm = 0;
  IterationProduct<Matrix> product(settings);
  for (int restart = 0; restart <= kMaxRestarts; ++restart) {
    double recurrence_norm = 0;
    const CgStop stop = run_pcg(a, b, x, preconditioner, product, target, initial_factor, restart == 0 ? &initial_norm : nullptr,
                                restart == 0 && settings.zero_start_when_better, settings.max_iterations, report.iterations,
                                recurrence_norm);
    const bool finite = x.allFinite();
    if (!finite) x = start;
    // Out of iterations (the dynamic step's budget: DynamicsSettings::iterations_per_step) nothing
    // decides on the residual, which is reported only: the recurrence's, without a product.
    if (stop == CgStop::out_of_iterations && finite && std::isfinite(recurrence_norm) && recurrence_norm > target) {
      r_norm = recurrence_norm;
      break;
    }
    residual(a, b, x, r);
    r_norm = r.norm();
    if (stop != CgStop::converged_recurrence || r_norm <= target) break;
  }
  report.relative_residual = r_norm / b_norm;
  report.initial_relative_residual = initial_norm / b_norm;
  report.converged = r_norm <= target;
  return report;
}

}  // namespace

SolveReport preconditioned_cg(const SparseMatrix& a, const Vector& b, Vector& x, const Preconditioner& preconditioner,
                              const SolveSettings& settings) {
  return preconditioned_cg_any(a, b, x, preconditioner, settings);
}

SolveReport preconditioned_cg(const BlockSparseMatrix<double>& a, const Vector& b, Vector& x, const Preconditioner& preconditioner,
                              const SolveSettings& settings) {
  return preconditioned_cg_any(a, b, x, preconditioner, settings);
}

SolveReport preconditioned_cg(const VertexOperator& a, const Vector& b, Vector& x, const Preconditioner& preconditioner,
                              const SolveSettings& settings) {
  return preconditioned_cg_any(a, b, x, preconditioner, settings);
}

}  // namespace cleave
