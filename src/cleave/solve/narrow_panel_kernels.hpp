#pragma once
// The dense kernels of a supernodal substitution for a few right-hand sides (K = 2 to 8
// columns, six for the direction field's Voigt tensors), stored by rows: row i of y is
// y[i * K .. i * K + K). A supernode's block of L is column-major with leading dimension
// `stride` (CHOLMOD's layout), and these loops read it once, straight from memory.
//
// Why not Eigen's products: for so few columns Eigen's matrix product and triangular solve
// copy ("pack") the factor's block before using it, which doubles the traffic on the largest
// operand, and a column-major y puts a scattered row's K values on K cache lines. With these
// kernels a 6-column substitution on the 44k tube's 1 GB factor reads it at ~2.5x the speed
// (tests/solve/solver_benchmark_test.cpp, DISABLED_Tube44kSubstitution). The loops are written
// for the compiler's vectoriser: the accumulators are small fixed arrays.
//
//   lower_solve_rows<6>(l, stride, w, y1);                  // L11 y1 = y1
//   panel_times_rows<6>(l + w, stride, below, w, y1, out);  // out = L21 y1 (row-major)
#include <Eigen/Core>

namespace cleave {

/// L11 y = y for the lower triangle L11 (w x w, column-major, leading dimension `stride`) and
/// the w rows of y (row-major, K values each).
template <int K>
void lower_solve_rows(const double* l, Eigen::Index stride, Eigen::Index w, double* y) {
  for (Eigen::Index j = 0; j < w; ++j) {
    const double* column = l + j * stride;
    double* yj = y + j * K;
    for (int c = 0; c < K; ++c) yj[c] /= column[j];
    for (Eigen::Index i = j + 1; i < w; ++i) {
      const double lij = column[i];
      double* yi = y + i * K;
      for (int c = 0; c < K; ++c) yi[c] -= lij * yj[c];
    }
  }
}

/// L11^T y = y for the same triangle and rows.
template <int K>
void upper_solve_rows(const double* l, Eigen::Index stride, Eigen::Index w, double* y) {
  for (Eigen::Index j = w; j-- > 0;) {
    const double* column = l + j * stride;
    double sum[K];
    for (int c = 0; c < K; ++c) sum[c] = y[j * K + c];
    for (Eigen::Index i = j + 1; i < w; ++i) {
      const double lij = column[i];
      const double* yi = y + i * K;
      for (int c = 0; c < K; ++c) sum[c] -= lij * yi[c];
    }
    for (int c = 0; c < K; ++c) y[j * K + c] = sum[c] / column[j];
  }
}

/// out = P x for the panel P (rows x width, column-major, leading dimension `stride`), x
/// (width rows of K, row-major) and out (rows of K, row-major). Eight rows at a time: their
/// K x 8 sums stay in registers (2 K vectors of four) while the panel's columns go by.
/// Rows ahead that panel_times_rows prefetches in each column (eight 64-byte lines).
constexpr Eigen::Index kPrefetchRows = 64;

template <int K>
void panel_times_rows(const double* p, Eigen::Index stride, Eigen::Index rows, Eigen::Index width, const double* x, double* out) {
  using Lanes = Eigen::Vector4d;
  Eigen::Index i0 = 0;
  for (; i0 + 8 <= rows; i0 += 8) {
    Lanes low[K], high[K];
    for (int c = 0; c < K; ++c) low[c] = high[c] = Lanes::Zero();
    for (Eigen::Index j = 0; j < width; ++j) {
      const double* column = p + j * stride + i0;
      // The columns are read a cache line at a time, too far apart for the hardware to
      // prefetch: ask for this column's line kPrefetchRows ahead.
      __builtin_prefetch(column + kPrefetchRows);
      const Lanes a = Eigen::Map<const Lanes>(column);
      const Lanes b = Eigen::Map<const Lanes>(column + 4);
      for (int c = 0; c < K; ++c) {
        const double xjc = x[j * K + c];
        low[c] += a * xjc;
        high[c] += b * xjc;
      }
    }
    for (int c = 0; c < K; ++c)
      for (int r = 0; r < 4; ++r) {
        out[(i0 + r) * K + c] = low[c][r];
        out[(i0 + 4 + r) * K + c] = high[c][r];
      }
  }
  for (; i0 < rows; ++i0) {
    double sum[K] = {};
    for (Eigen::Index j = 0; j < width; ++j)
      for (int c = 0; c < K; ++c) sum[c] += p[j * stride + i0] * x[j * K + c];
    for (int c = 0; c < K; ++c) out[i0 * K + c] = sum[c];
  }
}

/// out = P^T g for the same panel and g by columns (rows x K, column-major: g[c * rows + i]);
/// out has `width` rows of K (row-major). Each column of P is a contiguous dot product with
/// each column of g, four rows per step; two columns at a time (K <= 6) keep two memory streams
/// and two independent chains of multiply-adds in flight.
template <int K>
void panel_transpose_times(const double* p, Eigen::Index stride, Eigen::Index rows, Eigen::Index width, const double* g, double* out) {
  using Lanes = Eigen::Vector4d;
  constexpr Eigen::Index kColumns = K <= 6 ? 2 : 1;
  Eigen::Index j = 0;
  for (; j + kColumns <= width; j += kColumns) {
    Lanes lanes[kColumns][K];
    for (Eigen::Index q = 0; q < kColumns; ++q)
      for (int c = 0; c < K; ++c) lanes[q][c] = Lanes::Zero();
    Eigen::Index i = 0;
    for (; i + 4 <= rows; i += 4) {
      Lanes a[kColumns];
      for (Eigen::Index q = 0; q < kColumns; ++q) {
        __builtin_prefetch(p + (j + q) * stride + i + kPrefetchRows);
        a[q] = Eigen::Map<const Lanes>(p + (j + q) * stride + i);
      }
      for (int c = 0; c < K; ++c) {
        const Lanes gc = Eigen::Map<const Lanes>(g + c * rows + i);
        for (Eigen::Index q = 0; q < kColumns; ++q) lanes[q][c] += a[q].cwiseProduct(gc);
      }
    }
    for (Eigen::Index q = 0; q < kColumns; ++q) {
      const double* column = p + (j + q) * stride;
      for (int c = 0; c < K; ++c) {
        double sum = (lanes[q][c][0] + lanes[q][c][1]) + (lanes[q][c][2] + lanes[q][c][3]);
        for (Eigen::Index k = i; k < rows; ++k) sum += column[k] * g[c * rows + k];
        out[(j + q) * K + c] = sum;
      }
    }
  }
  for (; j < width; ++j) {
    const double* column = p + j * stride;
    for (int c = 0; c < K; ++c) {
      double sum = 0.0;
      for (Eigen::Index k = 0; k < rows; ++k) sum += column[k] * g[c * rows + k];
      out[j * K + c] = sum;
    }
  }
}

}  // namespace cleave
