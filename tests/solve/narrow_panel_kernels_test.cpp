// The substitution's kernels for a few right-hand sides stored by rows, against Eigen's dense
// products and triangular solves on the same data: odd row counts (the tails after the blocks
// of 8 and 4 rows), a leading dimension longer than the panel (a supernode's block), and every
// K the substitution dispatches to them (2 to 8).
#include "cleave/solve/narrow_panel_kernels.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace cleave {
namespace {

using RowsMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

constexpr Eigen::Index kStride = 41;  ///< leading dimension of the stored block: longer than any panel below
constexpr double kTolerance = 1e-13;

/// A column-major block of kStride rows and `columns` columns with a well-conditioned lower
/// triangle on top (diagonal 2 + |random|).
Eigen::MatrixXd stored_block(Eigen::Index columns) {
  Eigen::MatrixXd block = Eigen::MatrixXd::Random(kStride, columns);
  for (Eigen::Index j = 0; j < columns; ++j) block(j, j) = 2.0 + std::abs(block(j, j));
  return block;
}

template <int K>
void check_kernels() {
  for (const Eigen::Index width : {Eigen::Index{1}, Eigen::Index{3}, Eigen::Index{7}}) {
    const Eigen::MatrixXd block = stored_block(width);
    const auto triangle = block.topRows(width).triangularView<Eigen::Lower>();
    const RowsMatrix y = RowsMatrix::Random(width, K);

    RowsMatrix lower = y;
    lower_solve_rows<K>(block.data(), kStride, width, lower.data());
    EXPECT_LT((triangle * lower - y).norm(), kTolerance * y.norm()) << "K " << K << " width " << width;

    RowsMatrix upper = y;
    upper_solve_rows<K>(block.data(), kStride, width, upper.data());
    EXPECT_LT((triangle.transpose() * upper - y).norm(), kTolerance * y.norm()) << "K " << K << " width " << width;

    for (const Eigen::Index rows : {Eigen::Index{1}, Eigen::Index{8}, Eigen::Index{13}, Eigen::Index{kStride - width}}) {
      const auto panel = block.block(width, 0, rows, width);  // the rows below the triangle
      const double* panel_data = block.data() + width;
      RowsMatrix out(rows, K);
      panel_times_rows<K>(panel_data, kStride, rows, width, y.data(), out.data());
      const Eigen::MatrixXd product = panel * y;
      EXPECT_LT((out - product).norm(), kTolerance * product.norm()) << "K " << K << " rows " << rows << " width " << width;

      const Eigen::MatrixXd g = Eigen::MatrixXd::Random(rows, K);  // by columns
      RowsMatrix transposed(width, K);
      panel_transpose_times<K>(panel_data, kStride, rows, width, g.data(), transposed.data());
      const Eigen::MatrixXd reference = panel.transpose() * g;
      EXPECT_LT((transposed - reference).norm(), kTolerance * reference.norm()) << "K " << K << " rows " << rows << " width " << width;
    }
  }
}

TEST(NarrowPanelKernels, AgreeWithEigenForTwoToEightColumns) {
  check_kernels<2>();
  check_kernels<3>();
  check_kernels<4>();
  check_kernels<5>();
  check_kernels<6>();
  check_kernels<7>();
  check_kernels<8>();
}

}  // namespace
}  // namespace cleave
