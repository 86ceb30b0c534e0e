#include "cleave/solve/sparse_multiply.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace cleave {
namespace {

/// Rows per task: large enough that scheduling costs nothing next to the row work.
constexpr Eigen::Index kRowsPerTask = 2048;

template <typename RowFn>
void for_each_row_chunk(Eigen::Index rows, const RowFn& fn) {
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, rows, kRowsPerTask),
                    [&](const tbb::blocked_range<Eigen::Index>& range) { fn(range.begin(), range.end()); });
}

}  // namespace

void multiply(const SparseMatrix& a, const Vector& x, Vector& y) {
  y.resize(a.rows());
  const auto* outer = a.outerIndexPtr();
  const auto* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  const double* xp = x.data();
  double* yp = y.data();
  for_each_row_chunk(a.rows(), [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index row = begin; row < end; ++row) {
      double sum = 0;
      for (auto k = outer[row]; k < outer[row + 1]; ++k) sum += values[k] * xp[inner[k]];
      yp[row] = sum;
    }
  });
}

void residual(const SparseMatrix& a, const Vector& b, const Vector& x, Vector& r) {
  r.resize(a.rows());
  const auto* outer = a.outerIndexPtr();
  const auto* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  const double* xp = x.data();
  const double* bp = b.data();
  double* rp = r.data();
  for_each_row_chunk(a.rows(), [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index row = begin; row < end; ++row) {
      double sum = 0;
      for (auto k = outer[row]; k < outer[row + 1]; ++k) sum += values[k] * xp[inner[k]];
      rp[row] = bp[row] - sum;
    }
  });
}

}  // namespace cleave
