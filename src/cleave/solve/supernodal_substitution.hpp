#pragma once
// Forward and back substitution with a CHOLMOD supernodal Cholesky factor (A = P^T L L^T P) on
// all cores. CHOLMOD's own solve runs the supernodes one after another (a dense triangular solve
// and a matrix-vector product each); with one right-hand side that streams the whole factor
// (1 GB at 156,000 dofs) through one core, at that core's memory bandwidth. Here the supernodal
// elimination tree is split once into independent subtrees, solved in parallel, and the few
// supernodes above them (the top separators of the nested dissection, about half of the factor's
// bytes on 3-D grids) run their dense products over row blocks in parallel.
//
//   SupernodalSubstitution s(*factor);  // the schedule: once per symbolic analysis
//   s.solve(*factor, b);                // b <- A^-1 b, in place; any number of columns
//
// The schedule depends only on the factor's structure (supernodes, their rows, the permutation):
// it stays valid across numeric refactorizations with the same analysis. Results equal
// cholmod_solve(CHOLMOD_A, ...) to rounding (the same operations, other summation order) and do
// not depend on which thread ran what: the same schedule gives the same bits.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

struct cholmod_factor_struct;

namespace cleave {

class SupernodalSubstitution {
 public:
  /// Throws InputError unless `factor` is a supernodal LL^T factor with real double values and
  /// int indices (what cholmod_analyze + cholmod_factorize give with CHOLMOD_SUPERNODAL).
  explicit SupernodalSubstitution(const cholmod_factor_struct& factor);

  /// b <- A^-1 b for the factor this schedule was made from (or a refactorization of it with
  /// the same analysis). InputError when b's row count is not the factor's order.
  void solve(const cholmod_factor_struct& factor, Eigen::Ref<Eigen::MatrixXd> b) const;

  /// The factor's values rounded to single precision, at the same offsets (half the bytes: the
  /// substitution streams the factor, so solve_single takes about half the time of solve).
  /// InputError when the factor does not fit this schedule.
  std::vector<float> single_precision_values(const cholmod_factor_struct& factor) const;
  /// b <- A^-1 b in single precision with `values` (single_precision_values of this factor, or of
  /// a refactorization with the same analysis): b is rounded to float as it is permuted into the
  /// factor's order and the float result widened back. The relative error is about the float
  /// rounding times the condition number (4.6e-5 on the incised abdomen at 45k cells, 1e-6 on the
  /// tube), so callers check the residual in double and refine (CholmodSolver) or precondition
  /// with it (SparseCholesky::solve_single_precision). A b beyond float's range gives non-finite
  /// values. Wide kernels only. InputError when b's row count or the size of `values` does not
  /// fit the factor.
  void solve_single(const cholmod_factor_struct& factor, const std::vector<float>& values, Eigen::Ref<Eigen::MatrixXd> b) const;
  /// solve_single for a b that is zero outside the (unpermuted) rows `support`: the forward
  /// substitution visits only the supernodes above those rows (the others' rows of L^-1 P b are
  /// zero, so skipping them is exact), the back substitution all. A load that lives near a few
  /// incisions reaches a part of the factor's many small leaf supernodes. Entries of b outside
  /// `support` are not read (taken as zero). InputError as solve_single, and for rows out of range.
  void solve_single_supported(const cholmod_factor_struct& factor, const std::vector<float>& values,
                              const std::vector<Eigen::Index>& support, Eigen::Ref<Eigen::MatrixXd> b) const;

  /// W = L^-1 P E for the unit columns E = [e_r ...] of the (unpermuted) rows `rows`: what the
  /// forward substitution makes of them. Only the supernodes on the paths from those rows'
  /// supernodes to the roots are visited, and only their rows of W can be non-zero, so W comes
  /// back compact: row i of the result is permuted row reached_rows[i] of W (ascending; the rest
  /// is zero). A stroke's few hundred rows reach a small part of the factor (13 % of the rows at 45k
  /// cells) and cost a fraction of full solves. E^T A^-1 E = W^T W, and A^-1 E z is the back
  /// substitution of W z. InputError for rows out of range.
  Eigen::MatrixXd forward_unit_columns(const cholmod_factor_struct& factor, const std::vector<Eigen::Index>& rows,
                                       std::vector<Eigen::Index>& reached_rows) const;
  /// The same for a right-hand side that is zero outside the (unpermuted) rows `rows`: row i of
  /// `b_rows` is row rows[i] of b. Returns L^-1 P b on reached_rows, compact as above.
  Eigen::MatrixXd forward_sparse(const cholmod_factor_struct& factor, const std::vector<Eigen::Index>& rows,
                                 const Eigen::MatrixXd& b_rows, std::vector<Eigen::Index>& reached_rows) const;
  /// y = L^-1 P b (forward substitution of b, in permuted row order), on all cores.
  Eigen::MatrixXd forward_of(const cholmod_factor_struct& factor, const Eigen::MatrixXd& b) const;
  /// b = P^T L^-T y (back substitution of a forward-substituted y), on all cores.
  Eigen::MatrixXd backward_of(const cholmod_factor_struct& factor, Eigen::MatrixXd y) const;
  /// The (unpermuted) rows `rows` of backward_of(factor, y) only: the back substitution over the
  /// supernodes above those rows (as forward_unit_columns reaches them). Row i of the result is
  /// row rows[i]. InputError for rows out of range.
  Eigen::MatrixXd backward_rows(const cholmod_factor_struct& factor, Eigen::MatrixXd y, const std::vector<Eigen::Index>& rows) const;

  std::size_t order() const { return order_; }
  /// Independent subtrees solved in parallel, and the supernodes above them.
  std::size_t subtree_count() const { return subtree_begin_.size() - 1; }
  std::size_t top_supernode_count() const { return top_supernodes_.size(); }

 private:
  /// L y = y for the permuted right-hand sides y.
  void forward(const cholmod_factor_struct& factor, Eigen::MatrixXd& y) const;
  /// L^T y = y.
  void backward(const cholmod_factor_struct& factor, Eigen::MatrixXd& y) const;
  /// forward and backward with the supernode steps of `Kernels` (Eigen's products, or the
  /// narrow kernels on right-hand sides stored by rows); defined and used in the .cpp only.
  /// `values`: the factor's own (double) or a single-precision copy, as the kernels read.
  /// `reached`: when not null, only the supernodes it marks (those above the right-hand side's
  /// non-zero rows; the others would add zeros).
  template <typename Kernels>
  void forward_with(const cholmod_factor_struct& factor, const typename Kernels::Scalar* values, typename Kernels::Matrix& y,
                    const std::vector<std::uint8_t>* reached = nullptr) const;
  template <typename Kernels>
  void backward_with(const cholmod_factor_struct& factor, const typename Kernels::Scalar* values, typename Kernels::Matrix& y) const;

  std::size_t order_ = 0;
  std::size_t supernode_count_ = 0;
  /// Supernodes of subtree t, children before parents: subtree_order_[subtree_begin_[t] ..
  /// subtree_begin_[t + 1]), the heaviest subtrees first.
  std::vector<int> subtree_order_;
  std::vector<std::size_t> subtree_begin_;
  std::vector<int> top_supernodes_;  ///< ascending (children before parents)
  std::vector<int> top_slot_of_row_; ///< per permuted row: its slot among the top supernodes' columns, or -1
  std::vector<int> row_of_top_slot_;
  std::vector<int> parent_;             ///< supernodal elimination tree (-1 for a root)
  std::vector<int> supernode_of_column_;
  std::vector<int> inverse_permutation_;  ///< permuted position of each original row
  void check_order(const cholmod_factor_struct& factor, Eigen::Index rows) const;
  /// InputError unless `values` has the factor's size (a single_precision_values copy).
  void check_single_values(const cholmod_factor_struct& factor, const std::vector<float>& values) const;
  /// A mark per supernode on the paths from the (unpermuted) rows' supernodes to the roots.
  /// InputError for rows out of range.
  std::vector<std::uint8_t> supernodes_above_mask(const std::vector<Eigen::Index>& rows) const;
  /// The same supernodes, ascending.
  std::vector<int> supernodes_above(const std::vector<Eigen::Index>& rows) const;
};

}  // namespace cleave
