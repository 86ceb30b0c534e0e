#include "cleave/solve/forward_column_batches.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "cleave/core/error.hpp"
#include "cleave/solve/supernodal_substitution.hpp"

namespace cleave {
namespace {

constexpr double kBytesPerValue = sizeof(double);

/// Positions in `a` and in `b` (both ascending) of the values they share.
void shared_positions(const std::vector<Eigen::Index>& a, const std::vector<Eigen::Index>& b, std::vector<Eigen::Index>& in_a,
                      std::vector<Eigen::Index>& in_b) {
  in_a.clear();
  in_b.clear();
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i] < b[j]) {
      ++i;
    } else if (b[j] < a[i]) {
      ++j;
    } else {
      in_a.push_back(static_cast<Eigen::Index>(i++));
      in_b.push_back(static_cast<Eigen::Index>(j++));
    }
  }
}

}  // namespace

std::vector<Eigen::Index> ForwardColumnBatches::missing_rows(const std::vector<Eigen::Index>& changed) const {
  std::vector<Eigen::Index> missing;
  for (const Eigen::Index r : changed)
    if (column_of_row_.empty() || column_of_row_[static_cast<std::size_t>(r)] < 0) missing.push_back(r);
  return missing;
}

double ForwardColumnBatches::estimated_reach() const {
  // A batch reaches about as many rows as the largest kept one (the top separators dominate).
  double rows = 0;
  for (const Batch& batch : batches_) rows = std::max(rows, static_cast<double>(batch.reached.size()));
  return rows;
}

std::vector<Eigen::Index> ForwardColumnBatches::rows_to_make(const std::vector<Eigen::Index>& changed) const {
  std::vector<Eigen::Index> missing = missing_rows(changed);
  if (!overflow(missing.size(), estimated_reach())) return missing;
  return batches_to_forget(changed, missing.size(), estimated_reach()).empty() ? changed : missing;
}

std::vector<bool> ForwardColumnBatches::batches_to_forget(const std::vector<Eigen::Index>& changed, std::size_t added,
                                                          double added_rows) const {
  std::vector<bool> used(batches_.size(), false);
  for (const Eigen::Index r : changed) {
    const int column = column_of_row_.empty() ? -1 : column_of_row_[static_cast<std::size_t>(r)];
    if (column >= 0) used[static_cast<std::size_t>(batch_of_column_[static_cast<std::size_t>(column)])] = true;
  }
  std::vector<bool> drop(batches_.size(), false);
  std::size_t columns_left = columns();
  double bytes_left = bytes_;
  const auto fits = [&] { return !exceeds_bounds(columns_left, bytes_left, added, added_rows); };
  for (std::size_t b = 0; b < batches_.size() && !fits(); ++b) {
    if (used[b]) continue;
    drop[b] = true;
    columns_left -= static_cast<std::size_t>(batches_[b].w.cols());
    bytes_left -= kBytesPerValue * static_cast<double>(batches_[b].w.size());
  }
  if (!fits()) return {};
  return drop;
}

void ForwardColumnBatches::forget(const std::vector<bool>& drop) {
  std::vector<int> new_of_old(columns(), -1);
  std::vector<Eigen::Index> kept_old;
  std::vector<Batch> batches;
  batch_of_column_.clear();
  for (std::size_t b = 0; b < batches_.size(); ++b) {
    Batch& batch = batches_[b];
    if (drop[b]) {
      bytes_ -= kBytesPerValue * static_cast<double>(batch.w.size());
      continue;
    }
    const auto first_kept = static_cast<Eigen::Index>(kept_old.size());
    for (Eigen::Index c = 0; c < batch.w.cols(); ++c) {
      new_of_old[static_cast<std::size_t>(batch.first_column + c)] = static_cast<int>(kept_old.size());
      kept_old.push_back(batch.first_column + c);
      batch_of_column_.push_back(static_cast<int>(batches.size()));
    }
    batch.first_column = first_kept;
    batches.push_back(std::move(batch));
  }
  batches_ = std::move(batches);
  for (int& column : column_of_row_)
    if (column >= 0) column = new_of_old[static_cast<std::size_t>(column)];
  gram_ = Eigen::MatrixXd(gram_(kept_old, kept_old));
  known_ = decltype(known_)(known_(kept_old, kept_old));
}

bool ForwardColumnBatches::exceeds_bounds(std::size_t kept_columns, double kept_bytes, std::size_t added, double added_rows) const {
  return kept_columns + added > max_columns_ || kept_bytes + kBytesPerValue * added_rows * static_cast<double>(added) > max_bytes_;
}

bool ForwardColumnBatches::overflow(std::size_t added, double added_rows) const {
  if (added == 0 || batches_.empty()) return false;
  return exceeds_bounds(columns(), bytes_, added, added_rows);
}

void ForwardColumnBatches::clear() {
  bytes_ = 0;
  batches_.clear();
  batch_of_column_.clear();
  column_of_row_.clear();
  gram_.resize(0, 0);
  known_.resize(0, 0);
}

int ForwardColumnBatches::make(const SupernodalSubstitution& substitution, const cholmod_factor_struct& factor,
                               const std::vector<Eigen::Index>& changed) {
  std::vector<Eigen::Index> missing = missing_rows(changed);
  if (missing.empty()) return 0;
  // Past the bounds the kept batches this edit does not use give way; all of them when that is
  // not enough (then every changed row gets its column anew, in this batch).
  const auto make_room = [&](double added_rows) {
    if (!overflow(missing.size(), added_rows)) return true;
    const std::vector<bool> drop = batches_to_forget(changed, missing.size(), added_rows);
    if (drop.empty()) {
      clear();
      return false;
    }
    forget(drop);
    return true;
  };
  if (!make_room(estimated_reach())) missing = changed;
  Batch batch;
  batch.w = substitution.forward_unit_columns(factor, missing, batch.reached);
  if (!batch.w.allFinite()) {
    clear();
    return -1;
  }
  // A batch that reached more rows than estimated: the kept ones give way.
  if (!make_room(static_cast<double>(batch.reached.size())) && missing.size() != changed.size())
    return make(substitution, factor, changed);
  if (column_of_row_.empty()) column_of_row_.assign(substitution.order(), -1);
  const auto kept = static_cast<Eigen::Index>(columns());
  const auto added = static_cast<Eigen::Index>(missing.size());
  batch.first_column = kept;
  for (const Eigen::Index r : missing) {
    column_of_row_[static_cast<std::size_t>(r)] = static_cast<int>(batch_of_column_.size());
    batch_of_column_.push_back(static_cast<int>(batches_.size()));
  }
  bytes_ += kBytesPerValue * static_cast<double>(batch.w.size());
  batches_.push_back(std::move(batch));
  gram_.conservativeResize(kept + added, kept + added);
  known_.conservativeResizeLike(decltype(known_)::Zero(kept + added, kept + added));
  return static_cast<int>(added);
}

void ForwardColumnBatches::make_products(std::size_t first, const std::vector<Eigen::Index>& first_columns, std::size_t second,
                                         const std::vector<Eigen::Index>& second_columns) {
  const Batch& a = batches_[first];
  const Batch& b = batches_[second];
  std::vector<Eigen::Index> in_a, in_b;
  shared_positions(a.reached, b.reached, in_a, in_b);
  std::vector<Eigen::Index> local_a, local_b;
  for (const Eigen::Index c : first_columns) local_a.push_back(c - a.first_column);
  for (const Eigen::Index c : second_columns) local_b.push_back(c - b.first_column);
  const Eigen::MatrixXd products = a.w(in_a, local_a).transpose() * b.w(in_b, local_b);
  for (std::size_t i = 0; i < first_columns.size(); ++i)
    for (std::size_t j = 0; j < second_columns.size(); ++j) {
      const Eigen::Index p = first_columns[i];
      const Eigen::Index q = second_columns[j];
      gram_(p, q) = gram_(q, p) = products(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      known_(p, q) = known_(q, p) = 1;
    }
}

ForwardColumnBatches::Selection ForwardColumnBatches::select(const std::vector<Eigen::Index>& changed) {
  Selection selection;
  selection.size_ = static_cast<Eigen::Index>(changed.size());
  std::vector<Eigen::Index> columns;
  columns.reserve(changed.size());
  // The edit's columns grouped by batch (with their positions in `changed`).
  std::vector<std::vector<Eigen::Index>> columns_of_batch(batches_.size());
  std::vector<std::vector<Eigen::Index>> positions_of_batch(batches_.size());
  for (std::size_t i = 0; i < changed.size(); ++i) {
    const Eigen::Index row = changed[i];
    const int column = row >= 0 && static_cast<std::size_t>(row) < column_of_row_.size() ? column_of_row_[static_cast<std::size_t>(row)] : -1;
    if (column < 0) throw InputError(fmt::format("forward column batches: row {} has no column (make() them first)", row));
    columns.push_back(column);
    const auto batch = static_cast<std::size_t>(batch_of_column_[static_cast<std::size_t>(column)]);
    columns_of_batch[batch].push_back(column);
    positions_of_batch[batch].push_back(static_cast<Eigen::Index>(i));
  }
  // W^T W for each pair of batches with a pair of columns not known yet.
  for (std::size_t p = 0; p < batches_.size(); ++p)
    for (std::size_t q = p; q < batches_.size(); ++q) {
      if (columns_of_batch[p].empty() || columns_of_batch[q].empty()) continue;
      bool all_known = true;
      for (const Eigen::Index i : columns_of_batch[p])
        for (const Eigen::Index j : columns_of_batch[q]) all_known = all_known && known_(i, j) != 0;
      if (!all_known) make_products(p, columns_of_batch[p], q, columns_of_batch[q]);
    }
  selection.gram_ = gram_(columns, columns);
  for (std::size_t p = 0; p < batches_.size(); ++p) {
    if (columns_of_batch[p].empty()) continue;
    const Batch& batch = batches_[p];
    Selection::Part part;
    part.reached = &batch.reached;
    bool whole = static_cast<Eigen::Index>(columns_of_batch[p].size()) == batch.w.cols();
    for (std::size_t k = 0; whole && k < columns_of_batch[p].size(); ++k)
      whole = columns_of_batch[p][k] == batch.first_column + static_cast<Eigen::Index>(k);
    if (!whole) {
      std::vector<Eigen::Index> local;
      for (const Eigen::Index c : columns_of_batch[p]) local.push_back(c - batch.first_column);
      part.copied = batch.w(Eigen::all, local);
    }
    part.positions = std::move(positions_of_batch[p]);
    selection.parts_.push_back(std::move(part));
    if (whole) selection.parts_.back().w = &batch.w;
  }
  for (Selection::Part& part : selection.parts_)
    if (part.w == nullptr) part.w = &part.copied;
  return selection;
}

Eigen::MatrixXd ForwardColumnBatches::Selection::transpose_times(const Eigen::MatrixXd& y) const {
  Eigen::MatrixXd product(size_, y.cols());
  for (const Part& part : parts_) product(part.positions, Eigen::all) = part.w->transpose() * y(*part.reached, Eigen::all);
  return product;
}

void ForwardColumnBatches::Selection::subtract_times(Eigen::MatrixXd& y, const Eigen::MatrixXd& z) const {
  for (const Part& part : parts_) y(*part.reached, Eigen::all) -= *part.w * z(part.positions, Eigen::all);
}

}  // namespace cleave
