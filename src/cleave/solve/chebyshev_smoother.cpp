#include "cleave/solve/chebyshev_smoother.hpp"

#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>


namespace cleave {
namespace {

constexpr Eigen::Index kEntriesPerTask = 1 << 14;

std::vector<Mat3f> single_precision(const std::vector<Mat3>& blocks) {
  std::vector<Mat3f> out(blocks.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size(), kEntriesPerTask / 3), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t v = r.begin(); v < r.end(); ++v) out[v] = blocks[v].cast<float>();
  });
  return out;
}

/// d = c_d d + c_z z; x += d (or x = d when `assign`), in parallel chunks.
template <typename Scalar>
void update_direction(Scalar c_d, Scalar c_z, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z,
                      Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& d, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, bool assign) {
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, z.size(), kEntriesPerTask), [&](const tbb::blocked_range<Eigen::Index>& r) {
    const Eigen::Index n = r.end() - r.begin();
    auto ds = d.segment(r.begin(), n);
    ds = c_d * ds + c_z * z.segment(r.begin(), n);
    if (assign) x.segment(r.begin(), n) = ds;
    else x.segment(r.begin(), n) += ds;
  });
}

/// d = c_d d + c_z D^-1 (b - A x); x += d: for an operator in its own pass where it has one.
template <typename Matrix, typename Scalar>
void smoothing_step(const Matrix& a, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                    Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& d, Scalar c_d, Scalar c_z,
                    Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z) {
  if constexpr (std::is_same_v<Matrix, VertexOperator>) {
    a.chebyshev_step(inverse, b, x, d, c_d, c_z, z);
  } else {
    jacobi_residual(a, inverse, b, x, z);
    update_direction(c_d, c_z, z, d, x, false);
  }
}

}  // namespace

template <>
const std::vector<Mat3f>& ChebyshevSmoother::inverse_blocks<float>() const {
  return inverse_diagonal_single;
}
template <>
const std::vector<Mat3>& ChebyshevSmoother::inverse_blocks<double>() const {
  return inverse_diagonal;
}

namespace {

/// The warm start's vector on the new level (copies take their origin's entries); empty when
/// there is none that fits `rows`.
Eigen::VectorXd warm_vector(const ChebyshevWarmStart& warm, Eigen::Index rows) {
  if (warm.before == nullptr || warm.origin_of_new == nullptr) return {};
  const Eigen::VectorXd& old = warm.before->lambda_vector;
  const auto copies = static_cast<Eigen::Index>(warm.origin_of_new->size());
  if (old.size() == 0 || old.size() + 3 * copies != rows) return {};
  Eigen::VectorXd x(rows);
  x.head(old.size()) = old;
  for (Eigen::Index i = 0; i < copies; ++i) {
    const VertexId origin = (*warm.origin_of_new)[static_cast<std::size_t>(i)];
    if (origin < 0 || 3 * static_cast<Eigen::Index>(origin) >= old.size()) return {};
    x.segment<3>(old.size() + 3 * i) = old.segment<3>(3 * static_cast<Eigen::Index>(origin));
  }
  return x;
}

/// Sets s.lambda_max to lambda_max of D^-1 A by power iteration, enlarged by the safety factor,
/// and s.lambda_vector to the iteration's last vector: from the warm start's vector when there
/// is one (warm_power_iterations, and at least the old estimate), else from a fixed, non-special
/// start vector (deterministic).
template <typename Scalar, typename Matrix>
void estimate_lambda_max(const Matrix& a, const ChebyshevOptions& options, const ChebyshevWarmStart& warm, ChebyshevSmoother& s) {
  using VectorS = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  const auto& inverse = s.inverse_blocks<Scalar>();
  const Eigen::Index n = a.rows();
  VectorS x(n), z(n);
  const VectorS zero = VectorS::Zero(n);
  const Eigen::VectorXd start = warm_vector(warm, n);
  const bool warmed = start.size() == n && start.allFinite() && start.norm() > 0;
  if (warmed) {
    x = start.cast<Scalar>();
  } else {
    for (Eigen::Index i = 0; i < n; ++i) x[i] = static_cast<Scalar>(1.0 + 0.5 * std::sin(0.7 * static_cast<double>(i)));
  }
  double estimate = 1;
  const int iterations = warmed ? options.warm_power_iterations : options.power_iterations;
  for (int k = 0; k < iterations; ++k) {
    const double norm = static_cast<double>(x.norm());
    if (!(norm > 0) || !std::isfinite(norm)) break;
    x /= static_cast<Scalar>(norm);
    jacobi_residual(a, inverse, zero, x, z);  // z = -D^-1 A x
    z = -z;
    estimate = static_cast<double>(x.dot(z));  // Rayleigh-like quotient (x normalised)
    x = z;
  }
  const double growth = static_cast<double>(x.norm());
  if (std::isfinite(growth) && growth > estimate) estimate = growth;
  s.lambda_max = options.lambda_safety_factor * (std::isfinite(estimate) && estimate > 0 ? estimate : 1.0);
  if (warmed) s.lambda_max = std::max(s.lambda_max, warm.before->lambda_max);
  s.lambda_vector = x.template cast<double>();
  const double length = s.lambda_vector.norm();
  if (length > 0 && std::isfinite(length)) s.lambda_vector /= length;
  else s.lambda_vector.resize(0);
}

}  // namespace

template <typename Scalar>
ChebyshevSmoother make_chebyshev_smoother(const BlockSparseMatrix<Scalar>& a, const ChebyshevOptions& options,
                                          const ChebyshevWarmStart& warm) {
  ChebyshevSmoother s;
  s.options = options;
  s.set_inverse_diagonal(inverse_diagonal_blocks(a));
  estimate_lambda_max<Scalar>(a, options, warm, s);
  return s;
}

template <typename Scalar>
ChebyshevSmoother make_chebyshev_smoother(const VertexOperator& a, std::vector<Mat3> inverse_diagonal, const ChebyshevOptions& options,
                                          const ChebyshevWarmStart& warm) {
  ChebyshevSmoother s;
  s.options = options;
  s.set_inverse_diagonal(std::move(inverse_diagonal));
  estimate_lambda_max<Scalar>(a, options, warm, s);
  return s;
}

template ChebyshevSmoother make_chebyshev_smoother<float>(const VertexOperator&, std::vector<Mat3>, const ChebyshevOptions&,
                                                          const ChebyshevWarmStart&);
template ChebyshevSmoother make_chebyshev_smoother<double>(const VertexOperator&, std::vector<Mat3>, const ChebyshevOptions&,
                                                           const ChebyshevWarmStart&);
template ChebyshevSmoother make_chebyshev_smoother<float>(const BlockSparseMatrix<float>&, const ChebyshevOptions&,
                                                          const ChebyshevWarmStart&);
template ChebyshevSmoother make_chebyshev_smoother<double>(const BlockSparseMatrix<double>&, const ChebyshevOptions&,
                                                           const ChebyshevWarmStart&);

void ChebyshevSmoother::set_inverse_diagonal(std::vector<Mat3> inverse) {
  inverse_diagonal = std::move(inverse);
  inverse_diagonal_single = single_precision(inverse_diagonal);
}



template <typename Scalar>
void ChebyshevSmoother::smooth_from_zero(const BlockSparseMatrix<Scalar>& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                                         Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const {
  iterate(a, b, x, work, Start::from_zero);
}

template <typename Scalar>
void ChebyshevSmoother::smooth(const BlockSparseMatrix<Scalar>& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                               Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const {
  iterate(a, b, x, work, Start::from_x);
}

template <typename Scalar>
void ChebyshevSmoother::smooth_from_zero(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                                         Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const {
  iterate(a, b, x, work, Start::from_zero);
}

template <typename Scalar>
void ChebyshevSmoother::smooth(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                               Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work) const {
  iterate(a, b, x, work, Start::from_x);
}

// Chebyshev iteration on [lower, upper] (Saad, Iterative Methods, algorithm 12.1) with D^-1.
template <typename Matrix, typename Scalar>
void ChebyshevSmoother::iterate(const Matrix& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                                Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, ChebyshevWork<Scalar>& work, Start start) const {
  const auto& inverse = inverse_blocks<Scalar>();
  const double upper = lambda_max;
  const double lower = lambda_max / options.smoothing_range;
  const double theta = 0.5 * (upper + lower);
  const double delta = 0.5 * (upper - lower);
  const double sigma = theta / delta;
  double rho = 1.0 / sigma;
  const Eigen::Index n = b.size();
  if (start == Start::from_zero) {
    // x = d = D^-1 b / theta in one pass.
    x.resize(n);
    work.d.resize(n);
    const auto scale = static_cast<Scalar>(1.0 / theta);
    const auto blocks = static_cast<std::size_t>(n / 3);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, kEntriesPerTask / 3), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t v = r.begin(); v < r.end(); ++v) {
        const auto i = static_cast<Eigen::Index>(3 * v);
        const Eigen::Matrix<Scalar, 3, 1> step = scale * (inverse[v] * b.template segment<3>(i));
        work.d.template segment<3>(i) = step;
        x.template segment<3>(i) = step;
      }
    });
  } else {
    work.d.setZero(n);
    smoothing_step(a, inverse, b, x, work.d, Scalar{0}, static_cast<Scalar>(1.0 / theta), work.z);
  }
  for (int k = 1; k < options.degree; ++k) {
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    smoothing_step(a, inverse, b, x, work.d, static_cast<Scalar>(rho_next * rho), static_cast<Scalar>(2.0 * rho_next / delta), work.z);
    rho = rho_next;
  }
}

template void ChebyshevSmoother::smooth_from_zero<float>(const BlockSparseMatrix<float>&, const Eigen::VectorXf&, Eigen::VectorXf&,
                                                         ChebyshevWork<float>&) const;
template void ChebyshevSmoother::smooth_from_zero<double>(const BlockSparseMatrix<double>&, const Eigen::VectorXd&, Eigen::VectorXd&,
                                                          ChebyshevWork<double>&) const;
template void ChebyshevSmoother::smooth<float>(const BlockSparseMatrix<float>&, const Eigen::VectorXf&, Eigen::VectorXf&,
                                               ChebyshevWork<float>&) const;
template void ChebyshevSmoother::smooth<double>(const BlockSparseMatrix<double>&, const Eigen::VectorXd&, Eigen::VectorXd&,
                                                ChebyshevWork<double>&) const;
template void ChebyshevSmoother::smooth_from_zero<float>(const VertexOperator&, const Eigen::VectorXf&, Eigen::VectorXf&,
                                                         ChebyshevWork<float>&) const;
template void ChebyshevSmoother::smooth_from_zero<double>(const VertexOperator&, const Eigen::VectorXd&, Eigen::VectorXd&,
                                                          ChebyshevWork<double>&) const;
template void ChebyshevSmoother::smooth<float>(const VertexOperator&, const Eigen::VectorXf&, Eigen::VectorXf&,
                                               ChebyshevWork<float>&) const;
template void ChebyshevSmoother::smooth<double>(const VertexOperator&, const Eigen::VectorXd&, Eigen::VectorXd&,
                                                ChebyshevWork<double>&) const;

}  // namespace cleave
