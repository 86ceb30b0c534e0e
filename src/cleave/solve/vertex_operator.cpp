#include "cleave/solve/vertex_operator.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace cleave {
namespace {

constexpr std::size_t kVerticesPerTask = 2048;

template <typename Scalar>
void product_then_residual(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                           const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& r) {
  a.multiply(x, r);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, r.size(), 3 * kVerticesPerTask), [&](const tbb::blocked_range<Eigen::Index>& range) {
    const Eigen::Index n = range.end() - range.begin();
    r.segment(range.begin(), n) = b.segment(range.begin(), n) - r.segment(range.begin(), n);
  });
}

template <typename Scalar>
void product_then_jacobi(const VertexOperator& a, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                         const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                         Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z) {
  a.multiply(x, z);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, inverse_diagonal.size(), kVerticesPerTask),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t v = range.begin(); v < range.end(); ++v) {
                        const auto i = static_cast<Eigen::Index>(3 * v);
                        const Eigen::Matrix<Scalar, 3, 1> r = b.template segment<3>(i) - z.template segment<3>(i);
                        z.template segment<3>(i) = inverse_diagonal[v] * r;
                      }
                    });
}

}  // namespace

void VertexOperator::residual(const Eigen::VectorXf& b, const Eigen::VectorXf& x, Eigen::VectorXf& r) const {
  product_then_residual(*this, b, x, r);
}

void VertexOperator::residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
  product_then_residual(*this, b, x, r);
}

template <typename Scalar>
void residual(const VertexOperator& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
              const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& r) {
  a.residual(b, x, r);
}

namespace {

template <typename Scalar>
void jacobi_then_step(const VertexOperator& a, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                      const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                      Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& d, Scalar c_d, Scalar c_z, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z) {
  a.jacobi_residual(inverse_diagonal, b, x, z);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, z.size(), 3 * kVerticesPerTask), [&](const tbb::blocked_range<Eigen::Index>& r) {
    const Eigen::Index n = r.end() - r.begin();
    auto ds = d.segment(r.begin(), n);
    ds = c_d * ds + c_z * z.segment(r.begin(), n);
    x.segment(r.begin(), n) += ds;
  });
}

}  // namespace

void VertexOperator::chebyshev_step(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b, Eigen::VectorXf& x,
                                    Eigen::VectorXf& d, float c_d, float c_z, Eigen::VectorXf& work) const {
  jacobi_then_step(*this, inverse_diagonal, b, x, d, c_d, c_z, work);
}

void VertexOperator::chebyshev_step(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                    Eigen::VectorXd& d, double c_d, double c_z, Eigen::VectorXd& work) const {
  jacobi_then_step(*this, inverse_diagonal, b, x, d, c_d, c_z, work);
}

void VertexOperator::jacobi_residual(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b, const Eigen::VectorXf& x,
                                     Eigen::VectorXf& z) const {
  product_then_jacobi(*this, inverse_diagonal, b, x, z);
}

void VertexOperator::jacobi_residual(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                                     Eigen::VectorXd& z) const {
  product_then_jacobi(*this, inverse_diagonal, b, x, z);
}

template <typename Scalar>
void jacobi_residual(const VertexOperator& a, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                     const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                     Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z) {
  a.jacobi_residual(inverse_diagonal, b, x, z);
}

template void residual<float>(const VertexOperator&, const Eigen::VectorXf&, const Eigen::VectorXf&, Eigen::VectorXf&);
template void residual<double>(const VertexOperator&, const Eigen::VectorXd&, const Eigen::VectorXd&, Eigen::VectorXd&);
template void jacobi_residual<float>(const VertexOperator&, const std::vector<Mat3f>&, const Eigen::VectorXf&, const Eigen::VectorXf&,
                                     Eigen::VectorXf&);
template void jacobi_residual<double>(const VertexOperator&, const std::vector<Mat3>&, const Eigen::VectorXd&, const Eigen::VectorXd&,
                                      Eigen::VectorXd&);

}  // namespace cleave
