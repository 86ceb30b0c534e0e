#pragma once
// The forward-substituted unit columns W = L^-1 P E of the rows a low-rank update has changed
// since a factorization (A = P^T L L^T P), kept in batches, and their products W^T W.
//
// A diagonal change a = a0 + E D E^T of the factorized a0 is solved by
//   a^-1 b = P^T L^-T (y - W (I + D W^T W)^-1 D W^T y),   y = L^-1 P b.
// Column r of W is non-zero only on the supernodes above row r (SupernodalSubstitution::
// forward_unit_columns), so each batch keeps its columns on the rows they reach only. An edit
// makes columns only for its changed rows that have none (a stroke dragged one cell further: that
// cell's rows), and W^T W only for the pairs of columns an edit uses together that no earlier edit
// did, over the rows both batches reach (mostly the top separators).
//
//   ForwardColumnBatches kept;
//   kept.make(substitution, factor, changed);          // new columns for rows without one
//   const auto edit = kept.select(changed);            // this edit's columns and W^T W
//   z = lu(I + D edit.gram()).solve(D edit.transpose_times(y));  edit.subtract_times(y, z);
#include <Eigen/Core>
#include <cstddef>
#include <vector>

struct cholmod_factor_struct;

namespace cleave {

class SupernodalSubstitution;

class ForwardColumnBatches {
 public:
  /// At most `max_columns` columns and `max_bytes` of them; past either, make() first forgets the
  /// kept batches the edit does not use, oldest first (a stroke dragged on: the batches of the
  /// places it has left; its first place, whose rows every drag changes back, stays), and all of
  /// them only when that is not enough.
  ForwardColumnBatches(std::size_t max_columns, double max_bytes) : max_columns_(max_columns), max_bytes_(max_bytes) {}

  /// The rows of `changed` without a column, or all of them when their columns would exceed the
  /// bounds even without the kept batches the edit does not use (make() then forgets all).
  std::vector<Eigen::Index> rows_to_make(const std::vector<Eigen::Index>& changed) const;
  /// Makes the columns of rows_to_make(changed) as one batch. Returns how many it made, or -1 when
  /// they are not finite (then nothing is kept).
  int make(const SupernodalSubstitution& substitution, const cholmod_factor_struct& factor, const std::vector<Eigen::Index>& changed);
  void clear();
  std::size_t columns() const { return batch_of_column_.size(); }
  std::size_t batches() const { return batches_.size(); }

  /// The columns of one edit's changed rows (each must have one), in the order of `changed`.
  class Selection {
   public:
    Selection(Selection&&) = default;
    Selection& operator=(Selection&&) = default;
    Selection(const Selection&) = delete;  // its parts point into themselves
    Selection& operator=(const Selection&) = delete;
    ~Selection() = default;

    /// W_C^T y for y on all (permuted) rows: |C| x y.cols().
    Eigen::MatrixXd transpose_times(const Eigen::MatrixXd& y) const;
    /// y -= W_C z on the rows the columns reach.
    void subtract_times(Eigen::MatrixXd& y, const Eigen::MatrixXd& z) const;
    /// W_C^T W_C.
    const Eigen::MatrixXd& gram() const { return gram_; }

   private:
    friend class ForwardColumnBatches;
    Selection() = default;
    struct Part {  // the selected columns of one batch
      const std::vector<Eigen::Index>* reached;
      Eigen::MatrixXd copied;             // the batch's selected columns, unless all of them in order
      const Eigen::MatrixXd* w = nullptr;  // what to multiply with: the batch's own W or `copied`
      std::vector<Eigen::Index> positions;  // positions in C
    };
    std::vector<Part> parts_;
    Eigen::MatrixXd gram_;
    Eigen::Index size_ = 0;
  };
  /// This edit's columns; makes the products W^T W of its pairs that are not known yet. InputError
  /// for a row without a column.
  Selection select(const std::vector<Eigen::Index>& changed);

 private:
  struct Batch {
    std::vector<Eigen::Index> reached;  ///< ascending permuted rows its columns may be non-zero on
    Eigen::MatrixXd w;                  ///< reached.size() x its columns
    Eigen::Index first_column = 0;      ///< the kept column number of its first column
  };
  std::vector<Eigen::Index> missing_rows(const std::vector<Eigen::Index>& changed) const;
  /// Rows a new batch is expected to reach: as many as the largest kept one.
  double estimated_reach() const;
  /// Whether `added` more columns, reaching `added_rows` rows, exceed the bounds beside
  /// `kept_columns` columns of `kept_bytes`.
  bool exceeds_bounds(std::size_t kept_columns, double kept_bytes, std::size_t added, double added_rows) const;
  /// Whether `added` more columns, reaching `added_rows` rows, exceed the bounds beside the kept ones.
  bool overflow(std::size_t added, double added_rows) const;
  /// The batches to forget, oldest first among those none of whose columns `changed` uses, so that
  /// `added` columns reaching `added_rows` rows fit (per batch: true to forget); empty when
  /// forgetting all of those is not enough.
  std::vector<bool> batches_to_forget(const std::vector<Eigen::Index>& changed, std::size_t added, double added_rows) const;
  /// Forgets the batches marked in `forget`; the kept columns are renumbered in their order.
  void forget(const std::vector<bool>& forget);
  /// Fills gram_ and known_ for every pair of the columns `columns` of batches `first` and `second`.
  void make_products(std::size_t first, const std::vector<Eigen::Index>& first_columns, std::size_t second,
                     const std::vector<Eigen::Index>& second_columns);

  std::size_t max_columns_;
  double max_bytes_;
  double bytes_ = 0;
  std::vector<Batch> batches_;
  std::vector<int> batch_of_column_;  ///< per kept column: its batch
  std::vector<int> column_of_row_;  ///< per row: its column, or -1 (empty until the first batch)
  Eigen::MatrixXd gram_;            ///< W^T W where known_
  Eigen::Matrix<unsigned char, Eigen::Dynamic, Eigen::Dynamic> known_;
};

}  // namespace cleave
