#include "cleave/solve/supernodal_substitution.hpp"

#include <cholmod.h>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <queue>
#include <type_traits>
#include <utility>

#include "cleave/core/error.hpp"
#include "cleave/solve/narrow_panel_kernels.hpp"

namespace cleave {
namespace {

/// Subtrees per thread: enough that the heaviest one does not leave the other thread idle.
constexpr int kSubtreesPerThread = 4;
/// Supernodes above the subtrees with fewer entries than this run on one thread.
constexpr Eigen::Index kParallelSupernodeEntries = Eigen::Index{1} << 16;
/// Columns per block of a large supernode: each block's small triangle is solved on one thread,
/// the rows below it over all.
constexpr Eigen::Index kColumnBlock = 128;
/// Columns per thread below which a forward substitution of many columns keeps them together.
constexpr Eigen::Index kMinColumnsPerBlock = 8;
/// Entries of a large supernode's panel per parallel chunk of rows.
constexpr Eigen::Index kChunkEntries = Eigen::Index{1} << 15;

template <typename Scalar>
using DenseMatrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
/// Right-hand sides stored by rows (narrow_panel_kernels.hpp).
using RhsRows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// One supernode of a CHOLMOD factor: columns [first, first + columns) of L, stored as a dense
/// column-major rows x columns block whose row i is permuted row row_index[i] (the first
/// `columns` rows are the supernode's own columns). Scalar: the factor's double values, or a
/// single-precision copy of them at the same offsets.
template <typename Scalar>
struct SupernodeOf {
  Eigen::Index first = 0;
  Eigen::Index columns = 0;
  Eigen::Index rows = 0;
  const int* row_index = nullptr;
  const Scalar* entries = nullptr;

  Eigen::Map<const DenseMatrix<Scalar>> block() const { return {entries, rows, columns}; }
};
using Supernode = SupernodeOf<double>;

template <typename Scalar>
SupernodeOf<Scalar> supernode_of(const cholmod_factor& f, const Scalar* values, int s) {
  const auto* super = static_cast<const int*>(f.super);
  const auto* pi = static_cast<const int*>(f.pi);
  const auto* px = static_cast<const int*>(f.px);
  const auto* rows = static_cast<const int*>(f.s);
  const auto u = static_cast<std::size_t>(s);
  return {super[u], super[u + 1] - super[u], pi[u + 1] - pi[u], rows + pi[u], values + px[u]};
}

const double* values_of(const cholmod_factor& f) { return static_cast<const double*>(f.x); }

/// Row k of the factor's order is row Perm[k] of the caller's (k itself without a permutation).
Eigen::Index permuted_row(const cholmod_factor& f, Eigen::Index k) {
  const auto* perm = static_cast<const int*>(f.Perm);
  return perm != nullptr ? perm[k] : k;
}

/// The right-hand sides b in the factor's row order, in the precision Scalar.
template <typename Scalar, typename Rhs>
DenseMatrix<Scalar> to_factor_order(const cholmod_factor& f, const Rhs& b) {
  DenseMatrix<Scalar> y(b.rows(), b.cols());
  for (Eigen::Index k = 0; k < y.rows(); ++k) y.row(k) = b.row(permuted_row(f, k)).template cast<Scalar>();
  return y;
}

/// b = y back in the caller's row order (and precision).
template <typename Y, typename Rhs>
void from_factor_order(const cholmod_factor& f, const Y& y, Rhs&& b) {
  using Scalar = typename std::decay_t<Rhs>::Scalar;
  for (Eigen::Index k = 0; k < y.rows(); ++k) b.row(permuted_row(f, k)) = y.row(k).template cast<Scalar>();
}

/// Rows to give one parallel chunk of a panel `width` columns wide.
Eigen::Index chunk_rows(Eigen::Index width) { return std::max<Eigen::Index>(64, kChunkEntries / std::max<Eigen::Index>(width, 1)); }

/// t y = y for a triangle t (a triangularView of a diagonal block) and the rows y of one or more
/// right-hand sides. A single column takes Eigen's vector solve: its matrix solve packs the
/// triangle anew at every call (the forward substitution of one column took a quarter longer).
template <typename Triangle, typename Rows>
void solve_in_place(const Triangle& t, Rows&& y) {
  if (y.cols() == 1) {
    auto column = y.col(0);
    t.solveInPlace(column);
  } else {
    t.solveInPlace(y);
  }
}

/// L11 y1 = y1, then y(rows below) -= L21 y1: subtract_below(row, update) applies the update of
/// one permuted row below the diagonal block. One thread.
template <typename Scalar, typename Subtract>
void forward_supernode(const SupernodeOf<Scalar>& sn, DenseMatrix<Scalar>& y, const Subtract& subtract_below) {
  const auto l = sn.block();
  auto y1 = y.middleRows(sn.first, sn.columns);
  solve_in_place(l.topRows(sn.columns).template triangularView<Eigen::Lower>(), y1);
  const Eigen::Index below = sn.rows - sn.columns;
  if (below == 0) return;
  const DenseMatrix<Scalar> update = l.bottomRows(below) * y1;
  for (Eigen::Index i = 0; i < below; ++i) subtract_below(sn.row_index[sn.columns + i], update.row(i));
}

/// y1 -= L21^T y(rows below), then L11^T y1 = y1. One thread.
template <typename Scalar>
void backward_supernode(const SupernodeOf<Scalar>& sn, DenseMatrix<Scalar>& y) {
  const auto l = sn.block();
  auto y1 = y.middleRows(sn.first, sn.columns);
  const Eigen::Index below = sn.rows - sn.columns;
  if (below > 0) {
    DenseMatrix<Scalar> gathered(below, y.cols());
    for (Eigen::Index i = 0; i < below; ++i) gathered.row(i) = y.row(sn.row_index[sn.columns + i]);
    y1.noalias() -= l.bottomRows(below).transpose() * gathered;
  }
  solve_in_place(l.topRows(sn.columns).template triangularView<Eigen::Lower>().transpose(), y1);
}

/// forward_supernode of a large supernode: column blocks, the rows below each over all threads.
template <typename Scalar>
void forward_large_supernode(const SupernodeOf<Scalar>& sn, DenseMatrix<Scalar>& y) {
  const auto l = sn.block();
  for (Eigen::Index j0 = 0; j0 < sn.columns; j0 += kColumnBlock) {
    const Eigen::Index width = std::min(kColumnBlock, sn.columns - j0);
    auto yj = y.middleRows(sn.first + j0, width);
    solve_in_place(l.block(j0, j0, width, width).template triangularView<Eigen::Lower>(), yj);
    const Eigen::Index begin = j0 + width;
    if (begin == sn.rows) continue;
    const DenseMatrix<Scalar> yj_copy = yj;  // read by every chunk while they write other rows of y
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(begin, sn.rows, chunk_rows(width)),
                      [&](const tbb::blocked_range<Eigen::Index>& range) {
                        const Eigen::Index count = range.end() - range.begin();
                        const DenseMatrix<Scalar> update = l.block(range.begin(), j0, count, width) * yj_copy;
                        for (Eigen::Index i = 0; i < count; ++i) y.row(sn.row_index[range.begin() + i]) -= update.row(i);
                      });
  }
}

/// backward_supernode of a large supernode: column blocks from the last, each block's product
/// with the rows below reduced over all threads.
template <typename Scalar>
void backward_large_supernode(const SupernodeOf<Scalar>& sn, DenseMatrix<Scalar>& y) {
  using Dense = DenseMatrix<Scalar>;
  const auto l = sn.block();
  const Eigen::Index blocks = (sn.columns + kColumnBlock - 1) / kColumnBlock;
  for (Eigen::Index b = blocks - 1; b >= 0; --b) {
    const Eigen::Index j0 = b * kColumnBlock;
    const Eigen::Index width = std::min(kColumnBlock, sn.columns - j0);
    auto yj = y.middleRows(sn.first + j0, width);
    const Eigen::Index begin = j0 + width;
    if (begin < sn.rows) {
      const Dense zero = Dense::Zero(width, y.cols());
      // Deterministic: the chunks and their summation order do not depend on the scheduling.
      const Dense product = tbb::parallel_deterministic_reduce(
          tbb::blocked_range<Eigen::Index>(begin, sn.rows, chunk_rows(width)), zero,
          [&](const tbb::blocked_range<Eigen::Index>& range, Dense sum) {
            const Eigen::Index count = range.end() - range.begin();
            Dense gathered(count, y.cols());
            for (Eigen::Index i = 0; i < count; ++i) gathered.row(i) = y.row(sn.row_index[range.begin() + i]);
            sum.noalias() += l.block(range.begin(), j0, count, width).transpose() * gathered;
            return sum;
          },
          [](const Dense& a, const Dense& c) -> Dense { return a + c; }, tbb::simple_partitioner());
      yj -= product;
    }
    solve_in_place(l.block(j0, j0, width, width).template triangularView<Eigen::Lower>().transpose(), yj);
  }
}

/// backward_supernode, on all threads for a large supernode.
template <typename Scalar>
void backward_any_supernode(const SupernodeOf<Scalar>& sn, DenseMatrix<Scalar>& y) {
  if (sn.rows * sn.columns >= kParallelSupernodeEntries)
    backward_large_supernode(sn, y);
  else
    backward_supernode(sn, y);
}

/// The supernode steps with Eigen's dense products: any number of columns (the sparse updates'
/// hundreds of unit columns; one column takes Eigen's vector kernels), in the precision of the
/// factor's values they read (ScalarType: double, or float for the single-precision copy).
template <typename ScalarType>
struct WideKernelsOf {
  using Scalar = ScalarType;
  using Matrix = DenseMatrix<Scalar>;
  using Node = SupernodeOf<Scalar>;
  template <typename Subtract>
  static void forward(const Node& sn, Matrix& y, const Subtract& subtract_below) {
    forward_supernode(sn, y, subtract_below);
  }
  static void forward_large(const Node& sn, Matrix& y) { forward_large_supernode(sn, y); }
  static void backward(const Node& sn, Matrix& y) { backward_supernode(sn, y); }
  static void backward_any(const Node& sn, Matrix& y) { backward_any_supernode(sn, y); }
};
using WideKernels = WideKernelsOf<double>;

/// The same steps for K = 2 to 8 columns stored by rows, with the kernels of
/// narrow_panel_kernels.hpp (they read the factor without copying it first).
template <int K>
struct NarrowKernels {
  using Scalar = double;
  using Matrix = RhsRows;
  using Row = Eigen::Map<const Eigen::Matrix<double, 1, K>>;

  /// y(rows[i], c) for i < count as count x K by columns: g[c * count + i].
  static void gather_columns(const Matrix& y, const int* rows, Eigen::Index count, std::vector<double>& g) {
    g.resize(static_cast<std::size_t>(count * K));
    for (Eigen::Index i = 0; i < count; ++i) {
      const double* row = y.data() + Eigen::Index{rows[i]} * K;
      for (int c = 0; c < K; ++c) g[static_cast<std::size_t>(c * count + i)] = row[c];
    }
  }

  template <typename Subtract>
  static void forward(const Supernode& sn, Matrix& y, const Subtract& subtract_below) {
    double* y1 = y.data() + sn.first * K;
    lower_solve_rows<K>(sn.entries, sn.rows, sn.columns, y1);
    const Eigen::Index below = sn.rows - sn.columns;
    if (below == 0) return;
    thread_local std::vector<double> update;
    update.resize(static_cast<std::size_t>(below * K));
    panel_times_rows<K>(sn.entries + sn.columns, sn.rows, below, sn.columns, y1, update.data());
    for (Eigen::Index i = 0; i < below; ++i) subtract_below(sn.row_index[sn.columns + i], Row(update.data() + i * K));
  }

  static void forward_large(const Supernode& sn, Matrix& y) {
    for (Eigen::Index j0 = 0; j0 < sn.columns; j0 += kColumnBlock) {
      const Eigen::Index width = std::min(kColumnBlock, sn.columns - j0);
      double* yj = y.data() + (sn.first + j0) * K;
      const double* panel = sn.entries + j0 * sn.rows;  // columns j0 .. j0 + width, from row 0
      lower_solve_rows<K>(panel + j0, sn.rows, width, yj);
      const Eigen::Index begin = j0 + width;
      if (begin == sn.rows) continue;
      // The chunks read yj and write other rows of y (the rows below the supernode's columns).
      tbb::parallel_for(tbb::blocked_range<Eigen::Index>(begin, sn.rows, chunk_rows(width)),
                        [&](const tbb::blocked_range<Eigen::Index>& range) {
                          const Eigen::Index count = range.end() - range.begin();
                          thread_local std::vector<double> update;
                          update.resize(static_cast<std::size_t>(count * K));
                          panel_times_rows<K>(panel + range.begin(), sn.rows, count, width, yj, update.data());
                          for (Eigen::Index i = 0; i < count; ++i)
                            y.row(sn.row_index[range.begin() + i]) -= Row(update.data() + i * K);
                        });
    }
  }

  static void backward(const Supernode& sn, Matrix& y) {
    double* y1 = y.data() + sn.first * K;
    const Eigen::Index below = sn.rows - sn.columns;
    if (below > 0) {
      thread_local std::vector<double> gathered, product;
      gather_columns(y, sn.row_index + sn.columns, below, gathered);
      product.resize(static_cast<std::size_t>(sn.columns * K));
      panel_transpose_times<K>(sn.entries + sn.columns, sn.rows, below, sn.columns, gathered.data(), product.data());
      for (Eigen::Index i = 0; i < sn.columns * K; ++i) y1[i] -= product[static_cast<std::size_t>(i)];
    }
    upper_solve_rows<K>(sn.entries, sn.rows, sn.columns, y1);
  }

  static void backward_large(const Supernode& sn, Matrix& y) {
    const Eigen::Index blocks = (sn.columns + kColumnBlock - 1) / kColumnBlock;
    for (Eigen::Index b = blocks - 1; b >= 0; --b) {
      const Eigen::Index j0 = b * kColumnBlock;
      const Eigen::Index width = std::min(kColumnBlock, sn.columns - j0);
      double* yj = y.data() + (sn.first + j0) * K;
      const double* panel = sn.entries + j0 * sn.rows;
      const Eigen::Index begin = j0 + width;
      if (begin < sn.rows) {
        // Deterministic: the chunks and their summation order do not depend on the scheduling.
        const Eigen::VectorXd product = tbb::parallel_deterministic_reduce(
            tbb::blocked_range<Eigen::Index>(begin, sn.rows, chunk_rows(width)), Eigen::VectorXd::Zero(width * K).eval(),
            [&](const tbb::blocked_range<Eigen::Index>& range, Eigen::VectorXd sum) {
              const Eigen::Index count = range.end() - range.begin();
              thread_local std::vector<double> gathered;
              gather_columns(y, sn.row_index + range.begin(), count, gathered);
              Eigen::VectorXd part(width * K);
              panel_transpose_times<K>(panel + range.begin(), sn.rows, count, width, gathered.data(), part.data());
              sum += part;
              return sum;
            },
            [](const Eigen::VectorXd& a, const Eigen::VectorXd& c) -> Eigen::VectorXd { return a + c; },
            tbb::simple_partitioner());
        for (Eigen::Index i = 0; i < width * K; ++i) yj[i] -= product[i];
      }
      upper_solve_rows<K>(panel + j0, sn.rows, width, yj);
    }
  }

  static void backward_any(const Supernode& sn, Matrix& y) {
    if (sn.rows * sn.columns >= kParallelSupernodeEntries)
      backward_large(sn, y);
    else
      backward(sn, y);
  }
};

/// fn(NarrowKernels<K>{}, rows) on a copy of y stored by rows, the result copied back.
template <int K, typename Fn>
bool run_by_rows(Eigen::MatrixXd& y, const Fn& fn) {
  RhsRows rows = y;
  fn(NarrowKernels<K>{}, rows);
  y = rows;
  return true;
}

/// run_by_rows for y with 2 to 8 columns; false (y untouched) for other column counts.
template <typename Fn>
bool run_narrow(Eigen::MatrixXd& y, const Fn& fn) {
  switch (y.cols()) {
    case 2: return run_by_rows<2>(y, fn);
    case 3: return run_by_rows<3>(y, fn);
    case 4: return run_by_rows<4>(y, fn);
    case 5: return run_by_rows<5>(y, fn);
    case 6: return run_by_rows<6>(y, fn);
    case 7: return run_by_rows<7>(y, fn);
    case 8: return run_by_rows<8>(y, fn);
    default: return false;
  }
}

/// The forward steps of `supernodes` in their order (ascending: children before parents) on y.
template <typename Kernels>
void forward_in_order(const std::vector<Supernode>& supernodes, typename Kernels::Matrix& y) {
  for (const Supernode& sn : supernodes) {
    if (sn.rows * sn.columns >= kParallelSupernodeEntries)
      Kernels::forward_large(sn, y);
    else
      Kernels::forward(sn, y, [&](int row, const auto& update) { y.row(row) -= update; });
  }
}

/// forward_in_order with the wide kernels, the columns of y split into one block per thread:
/// the columns are independent, and a stroke's tens of unit columns made the supernodes' small
/// triangles and products run on one thread (only the large supernodes' rows were shared out).
/// The blocks depend only on the thread count, so the same machine gives the same bits.
void forward_in_order_by_column_blocks(const std::vector<Supernode>& supernodes, Eigen::MatrixXd& y) {
  const Eigen::Index threads = std::max(1, tbb::this_task_arena::max_concurrency());
  const Eigen::Index blocks = std::min(threads, y.cols() / kMinColumnsPerBlock);
  if (blocks < 2) return forward_in_order<WideKernels>(supernodes, y);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, blocks, 1),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index block = range.begin(); block < range.end(); ++block) {
                        const Eigen::Index first = block * y.cols() / blocks;
                        const Eigen::Index count = (block + 1) * y.cols() / blocks - first;
                        Eigen::MatrixXd part = y.middleCols(first, count);
                        forward_in_order<WideKernels>(supernodes, part);
                        y.middleCols(first, count) = part;
                      }
                    },
                    tbb::simple_partitioner());
}

}  // namespace

SupernodalSubstitution::SupernodalSubstitution(const cholmod_factor& factor) {
  if (!factor.is_super || !factor.is_ll)
    throw InputError("supernodal substitution: expected a supernodal LL^T CHOLMOD factor (CHOLMOD_SUPERNODAL)");
  if (factor.xtype != CHOLMOD_REAL || factor.dtype != CHOLMOD_DOUBLE || factor.itype != CHOLMOD_INT)
    throw InputError("supernodal substitution: expected a factor with real double values and int indices");
  order_ = factor.n;
  supernode_count_ = factor.nsuper;
  const auto* super = static_cast<const int*>(factor.super);
  const auto* pi = static_cast<const int*>(factor.pi);
  const auto* rows = static_cast<const int*>(factor.s);

  // The supernodal elimination tree: a supernode's parent owns the first row below its columns.
  std::vector<int>& supernode_of_column = supernode_of_column_;
  supernode_of_column.assign(order_, 0);
  for (std::size_t s = 0; s < supernode_count_; ++s)
    for (int k = super[s]; k < super[s + 1]; ++k) supernode_of_column[static_cast<std::size_t>(k)] = static_cast<int>(s);
  std::vector<int> parent(supernode_count_, -1);
  std::vector<double> subtree_entries(supernode_count_, 0.0);
  std::vector<std::vector<int>> children(supernode_count_);
  std::vector<int> roots;
  for (std::size_t s = 0; s < supernode_count_; ++s) {
    const int columns = super[s + 1] - super[s];
    const int row_count = pi[s + 1] - pi[s];
    subtree_entries[s] += static_cast<double>(columns) * row_count;
    if (row_count > columns) {
      const int below_first = *std::min_element(rows + pi[s] + columns, rows + pi[s + 1]);
      parent[s] = supernode_of_column[static_cast<std::size_t>(below_first)];
      if (parent[s] <= static_cast<int>(s)) throw InputError("supernodal substitution: the factor's supernodes are not in elimination order");
      subtree_entries[static_cast<std::size_t>(parent[s])] += subtree_entries[s];
      children[static_cast<std::size_t>(parent[s])].push_back(static_cast<int>(s));
    } else {
      roots.push_back(static_cast<int>(s));
    }
  }

  // Split from the roots down until no subtree holds more than its share of the entries.
  double total = 0;
  for (const int r : roots) total += subtree_entries[static_cast<std::size_t>(r)];
  const double share = total / (kSubtreesPerThread * std::max(1, tbb::this_task_arena::max_concurrency()));
  const auto lighter = [&](int a, int b) { return subtree_entries[static_cast<std::size_t>(a)] < subtree_entries[static_cast<std::size_t>(b)]; };
  std::priority_queue<int, std::vector<int>, decltype(lighter)> candidates(lighter, roots);
  while (!candidates.empty()) {
    const int s = candidates.top();
    if (subtree_entries[static_cast<std::size_t>(s)] <= share || children[static_cast<std::size_t>(s)].empty()) break;
    candidates.pop();
    top_supernodes_.push_back(s);
    for (const int c : children[static_cast<std::size_t>(s)]) candidates.push(c);
  }
  std::sort(top_supernodes_.begin(), top_supernodes_.end());
  parent_ = parent;
  const auto* perm = static_cast<const int*>(factor.Perm);
  inverse_permutation_.resize(order_);
  for (std::size_t k = 0; k < order_; ++k) inverse_permutation_[perm != nullptr ? static_cast<std::size_t>(perm[k]) : k] = static_cast<int>(k);

  subtree_begin_.push_back(0);
  for (; !candidates.empty(); candidates.pop()) {  // heaviest first
    const std::size_t begin = subtree_order_.size();
    subtree_order_.push_back(candidates.top());
    for (std::size_t i = begin; i < subtree_order_.size(); ++i)
      for (const int c : children[static_cast<std::size_t>(subtree_order_[i])]) subtree_order_.push_back(c);
    std::sort(subtree_order_.begin() + static_cast<std::ptrdiff_t>(begin), subtree_order_.end());  // children first
    subtree_begin_.push_back(subtree_order_.size());
  }

  top_slot_of_row_.assign(order_, -1);
  for (const int s : top_supernodes_)
    for (int k = super[s]; k < super[s + 1]; ++k) {
      top_slot_of_row_[static_cast<std::size_t>(k)] = static_cast<int>(row_of_top_slot_.size());
      row_of_top_slot_.push_back(k);
    }
}

void SupernodalSubstitution::forward(const cholmod_factor& factor, Eigen::MatrixXd& y) const {
  const bool narrow =
      run_narrow(y, [&](auto kernels, RhsRows& rows) { forward_with<decltype(kernels)>(factor, values_of(factor), rows); });
  if (!narrow) forward_with<WideKernels>(factor, values_of(factor), y);
}

void SupernodalSubstitution::backward(const cholmod_factor& factor, Eigen::MatrixXd& y) const {
  const bool narrow =
      run_narrow(y, [&](auto kernels, RhsRows& rows) { backward_with<decltype(kernels)>(factor, values_of(factor), rows); });
  if (!narrow) backward_with<WideKernels>(factor, values_of(factor), y);
}

template <typename Kernels>
void SupernodalSubstitution::forward_with(const cholmod_factor& factor, const typename Kernels::Scalar* values,
                                          typename Kernels::Matrix& y, const std::vector<std::uint8_t>* reached) const {
  const auto visits = [&](int s) { return reached == nullptr || (*reached)[static_cast<std::size_t>(s)] != 0; };
  using Matrix = typename Kernels::Matrix;
  // Forward: the subtrees in parallel; each one's updates of the rows above it go to its own
  // sums, subtracted in subtree order before the top supernodes run (the same rounding whatever
  // thread ran which subtree).
  const auto top_rows = static_cast<Eigen::Index>(row_of_top_slot_.size());
  std::vector<Matrix> above(subtree_count());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, subtree_count(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t t = range.begin(); t < range.end(); ++t) {
                        Matrix& sums = above[t];  // made at its first update: a root (a held dof) has none
                        for (std::size_t i = subtree_begin_[t]; i < subtree_begin_[t + 1]; ++i) {
                          if (!visits(subtree_order_[i])) continue;
                          Kernels::forward(supernode_of(factor, values, subtree_order_[i]), y, [&](int row, const auto& update) {
                            const int slot = top_slot_of_row_[static_cast<std::size_t>(row)];
                            if (slot >= 0) {
                              if (sums.size() == 0) sums.setZero(top_rows, y.cols());
                              sums.row(slot) += update;
                            } else {
                              y.row(row) -= update;
                            }
                          });
                        }
                      }
                    },
                    tbb::simple_partitioner());
  for (const Matrix& sums : above)
    if (sums.size() > 0)
      for (Eigen::Index slot = 0; slot < top_rows; ++slot) y.row(row_of_top_slot_[static_cast<std::size_t>(slot)]) -= sums.row(slot);
  for (const int s : top_supernodes_) {
    if (!visits(s)) continue;
    const auto sn = supernode_of(factor, values, s);
    if (sn.rows * sn.columns >= kParallelSupernodeEntries)
      Kernels::forward_large(sn, y);
    else
      Kernels::forward(sn, y, [&](int row, const auto& update) { y.row(row) -= update; });
  }
}

template <typename Kernels>
void SupernodalSubstitution::backward_with(const cholmod_factor& factor, const typename Kernels::Scalar* values,
                                           typename Kernels::Matrix& y) const {
  // Backward: the top supernodes from the root down, then the subtrees in parallel (each reads
  // the rows above it, already final, and writes only its own).
  for (auto it = top_supernodes_.rbegin(); it != top_supernodes_.rend(); ++it)
    Kernels::backward_any(supernode_of(factor, values, *it), y);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, subtree_count(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t t = range.begin(); t < range.end(); ++t)
                        for (std::size_t i = subtree_begin_[t + 1]; i-- > subtree_begin_[t];)
                          Kernels::backward(supernode_of(factor, values, subtree_order_[i]), y);
                    },
                    tbb::simple_partitioner());
}

void SupernodalSubstitution::check_order(const cholmod_factor& factor, Eigen::Index rows) const {
  if (static_cast<std::size_t>(rows) != order_ || factor.n != order_ || factor.nsuper != supernode_count_)
    throw InputError(fmt::format("supernodal substitution: right-hand side has {} rows and the factor order {}; the schedule "
                                 "was made for order {} with {} supernodes",
                                 rows, factor.n, order_, supernode_count_));
}

void SupernodalSubstitution::solve(const cholmod_factor& factor, Eigen::Ref<Eigen::MatrixXd> b) const {
  check_order(factor, b.rows());
  Eigen::MatrixXd y = to_factor_order<double>(factor, b);

  // Both sweeps on one copy by rows (2 to 8 columns), not a copy each.
  const bool narrow = run_narrow(y, [&](auto kernels, RhsRows& rows) {
    forward_with<decltype(kernels)>(factor, values_of(factor), rows);
    backward_with<decltype(kernels)>(factor, values_of(factor), rows);
  });
  if (!narrow) {
    forward_with<WideKernels>(factor, values_of(factor), y);
    backward_with<WideKernels>(factor, values_of(factor), y);
  }
  from_factor_order(factor, y, b);
}

std::vector<float> SupernodalSubstitution::single_precision_values(const cholmod_factor& factor) const {
  check_order(factor, static_cast<Eigen::Index>(order_));
  const double* values = values_of(factor);
  std::vector<float> out(factor.xsize);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), std::size_t{1} << 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) out[i] = static_cast<float>(values[i]);
  });
  return out;
}

void SupernodalSubstitution::check_single_values(const cholmod_factor& factor, const std::vector<float>& values) const {
  if (values.size() != factor.xsize)
    throw InputError(fmt::format("supernodal substitution: {} single-precision values for a factor of {}; expected a copy "
                                 "made by single_precision_values of this factor",
                                 values.size(), factor.xsize));
}

void SupernodalSubstitution::solve_single(const cholmod_factor& factor, const std::vector<float>& values,
                                          Eigen::Ref<Eigen::MatrixXd> b) const {
  check_order(factor, b.rows());
  check_single_values(factor, values);
  Eigen::MatrixXf y = to_factor_order<float>(factor, b);
  forward_with<WideKernelsOf<float>>(factor, values.data(), y);
  backward_with<WideKernelsOf<float>>(factor, values.data(), y);
  from_factor_order(factor, y, b);
}

void SupernodalSubstitution::solve_single_supported(const cholmod_factor& factor, const std::vector<float>& values,
                                                    const std::vector<Eigen::Index>& support, Eigen::Ref<Eigen::MatrixXd> b) const {
  check_order(factor, b.rows());
  check_single_values(factor, values);
  const std::vector<std::uint8_t> reached = supernodes_above_mask(support);
  Eigen::MatrixXf y = Eigen::MatrixXf::Zero(b.rows(), b.cols());
  for (const Eigen::Index r : support) y.row(inverse_permutation_[static_cast<std::size_t>(r)]) = b.row(r).cast<float>();
  forward_with<WideKernelsOf<float>>(factor, values.data(), y, &reached);
  backward_with<WideKernelsOf<float>>(factor, values.data(), y);
  from_factor_order(factor, y, b);
}

Eigen::MatrixXd SupernodalSubstitution::forward_of(const cholmod_factor& factor, const Eigen::MatrixXd& b) const {
  check_order(factor, b.rows());
  Eigen::MatrixXd y = to_factor_order<double>(factor, b);
  forward(factor, y);
  return y;
}

Eigen::MatrixXd SupernodalSubstitution::backward_of(const cholmod_factor& factor, Eigen::MatrixXd y) const {
  check_order(factor, y.rows());
  backward(factor, y);
  Eigen::MatrixXd b(y.rows(), y.cols());
  from_factor_order(factor, y, b);
  return b;
}

Eigen::MatrixXd SupernodalSubstitution::forward_unit_columns(const cholmod_factor& factor, const std::vector<Eigen::Index>& rows,
                                                             std::vector<Eigen::Index>& reached_rows) const {
  const auto k = static_cast<Eigen::Index>(rows.size());
  return forward_sparse(factor, rows, Eigen::MatrixXd::Identity(k, k), reached_rows);
}

Eigen::MatrixXd SupernodalSubstitution::forward_sparse(const cholmod_factor& factor, const std::vector<Eigen::Index>& rows,
                                                       const Eigen::MatrixXd& b_rows, std::vector<Eigen::Index>& reached_rows) const {
  check_order(factor, static_cast<Eigen::Index>(order_));
  if (b_rows.rows() != static_cast<Eigen::Index>(rows.size()))
    throw InputError(fmt::format("supernodal substitution: {} rows of values for {} rows", b_rows.rows(), rows.size()));
  const std::vector<int> visit = supernodes_above(rows);
  // Compact rows: the reached supernodes' columns one after another (each supernode's stay
  // contiguous), and each visited supernode's row indices renumbered to them.
  const auto* super = static_cast<const int*>(factor.super);
  std::vector<int> slot(order_, -1);
  reached_rows.clear();
  for (const int s : visit)
    for (int k = super[s]; k < super[s + 1]; ++k) {
      slot[static_cast<std::size_t>(k)] = static_cast<int>(reached_rows.size());
      reached_rows.push_back(k);
    }
  const double* values = values_of(factor);
  std::vector<Supernode> compact(visit.size());
  std::size_t index_count = 0;
  for (std::size_t i = 0; i < visit.size(); ++i) {
    compact[i] = supernode_of(factor, values, visit[i]);
    index_count += static_cast<std::size_t>(compact[i].rows);
  }
  std::vector<int> renumbered;
  renumbered.reserve(index_count);
  for (Supernode& sn : compact) {
    const std::size_t begin = renumbered.size();
    for (Eigen::Index i = 0; i < sn.rows; ++i) renumbered.push_back(slot[static_cast<std::size_t>(sn.row_index[i])]);
    sn.first = slot[static_cast<std::size_t>(sn.first)];
    sn.row_index = renumbered.data() + begin;
  }
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(reached_rows.size()), b_rows.cols());
  for (std::size_t i = 0; i < rows.size(); ++i)
    w.row(slot[static_cast<std::size_t>(inverse_permutation_[static_cast<std::size_t>(rows[i])])]) += b_rows.row(static_cast<Eigen::Index>(i));
  if (!run_narrow(w, [&](auto kernels, RhsRows& by_rows) { forward_in_order<decltype(kernels)>(compact, by_rows); }))
    forward_in_order_by_column_blocks(compact, w);
  return w;
}

std::vector<std::uint8_t> SupernodalSubstitution::supernodes_above_mask(const std::vector<Eigen::Index>& rows) const {
  const auto n = static_cast<Eigen::Index>(order_);
  // Each row's supernode and all above it (the rows below a supernode's columns belong to its
  // ancestors); a path ends where an earlier row's path was.
  std::vector<std::uint8_t> reached(supernode_count_, 0);
  for (const Eigen::Index r : rows) {
    if (r < 0 || r >= n) throw InputError(fmt::format("supernodal substitution: row {} is outside 0 to {}", r, n - 1));
    for (int s = supernode_of_column_[static_cast<std::size_t>(inverse_permutation_[static_cast<std::size_t>(r)])];
         s >= 0 && reached[static_cast<std::size_t>(s)] == 0; s = parent_[static_cast<std::size_t>(s)])
      reached[static_cast<std::size_t>(s)] = 1;
  }
  return reached;
}

std::vector<int> SupernodalSubstitution::supernodes_above(const std::vector<Eigen::Index>& rows) const {
  const std::vector<std::uint8_t> reached = supernodes_above_mask(rows);
  std::vector<int> visit;  // in elimination order
  for (std::size_t s = 0; s < reached.size(); ++s)
    if (reached[s] != 0) visit.push_back(static_cast<int>(s));
  return visit;
}

Eigen::MatrixXd SupernodalSubstitution::backward_rows(const cholmod_factor& factor, Eigen::MatrixXd y,
                                                      const std::vector<Eigen::Index>& rows) const {
  check_order(factor, y.rows());
  const std::vector<int> visit = supernodes_above(rows);
  const double* values = values_of(factor);
  // From the root down: each supernode reads the rows below its columns, its ancestors', done before it.
  const auto back_from_root = [&](auto kernels, auto& rhs) {
    for (auto it = visit.rbegin(); it != visit.rend(); ++it) decltype(kernels)::backward_any(supernode_of(factor, values, *it), rhs);
  };
  if (!run_narrow(y, [&](auto kernels, RhsRows& by_rows) { back_from_root(kernels, by_rows); })) back_from_root(WideKernels{}, y);
  Eigen::MatrixXd x(static_cast<Eigen::Index>(rows.size()), y.cols());
  for (std::size_t i = 0; i < rows.size(); ++i)
    x.row(static_cast<Eigen::Index>(i)) = y.row(inverse_permutation_[static_cast<std::size_t>(rows[i])]);
  return x;
}

}  // namespace cleave
