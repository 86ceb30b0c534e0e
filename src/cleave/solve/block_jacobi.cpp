#include "cleave/solve/block_jacobi.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

constexpr std::size_t kVerticesPerTask = 1024;
/// A block counts as singular when |det| falls below this times its norm cubed (scale free).
constexpr double kRelativeDeterminantFloor = 1e-14;

}  // namespace

Mat3 inverse_or_identity(const Mat3& block) {
  Mat3 inverse;
  bool invertible = false;
  double determinant = 0;
  const double scale = block.norm();
  block.computeInverseAndDetWithCheck(inverse, determinant, invertible, kRelativeDeterminantFloor * scale * scale * scale);
  return (invertible && inverse.allFinite()) ? inverse : Mat3::Identity();
}

template <typename Scalar>
std::vector<Mat3> inverse_diagonal_blocks(const BlockSparseMatrix<Scalar>& a) {
  const auto vertices = static_cast<std::size_t>(a.block_rows());
  std::vector<Mat3> out(vertices);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices, kVerticesPerTask), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t v = range.begin(); v < range.end(); ++v) {
      const auto first = a.column.begin() + a.row_start[v];
      const auto last = a.column.begin() + a.row_start[v + 1];
      const auto found = std::lower_bound(first, last, static_cast<std::int32_t>(v));
      Mat3 block = Mat3::Zero();
      if (found != last && *found == static_cast<std::int32_t>(v))
        block = Eigen::Map<const Eigen::Matrix<Scalar, 3, 3, Eigen::RowMajor>>(a.values.data() + 9 * (found - a.column.begin()))
                    .template cast<double>();
      out[v] = inverse_or_identity(block);
    }
  });
  return out;
}

template std::vector<Mat3> inverse_diagonal_blocks<float>(const BlockSparseMatrix<float>&);
template std::vector<Mat3> inverse_diagonal_blocks<double>(const BlockSparseMatrix<double>&);

BlockJacobi block_jacobi(const SparseMatrix& a) {
  if (a.rows() % 3 != 0 || a.rows() != a.cols())
    throw InputError(fmt::format("block Jacobi: matrix is {} x {}; expected a square matrix with 3 dofs per vertex", a.rows(),
                                 a.cols()));
  BlockJacobi d;
  const auto vertices = static_cast<std::size_t>(a.rows() / 3);
  d.inverse_blocks.resize(vertices);
  const auto* outer = a.outerIndexPtr();
  const auto* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices, kVerticesPerTask), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t v = range.begin(); v < range.end(); ++v) {
      Mat3 block = Mat3::Zero();
      const auto first = static_cast<Eigen::Index>(3 * v);
      for (int i = 0; i < 3; ++i)
        for (auto k = outer[first + i]; k < outer[first + i + 1]; ++k) {
          const auto column = static_cast<Eigen::Index>(inner[k]) - first;
          if (column >= 0 && column < 3) block(i, column) = values[k];
        }
      d.inverse_blocks[v] = inverse_or_identity(block);
    }
  });
  return d;
}

void BlockJacobi::apply(const Vector& r, Vector& z) const {
  z.resize(r.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, inverse_blocks.size(), kVerticesPerTask),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t v = range.begin(); v < range.end(); ++v) {
                        const auto i = static_cast<Eigen::Index>(3 * v);
                        z.segment<3>(i) = inverse_blocks[v] * r.segment<3>(i);
                      }
                    });
}

}  // namespace cleave
