#include "cleave/solve/multigrid_preconditioner.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "cleave/core/error.hpp"
#include "cleave/solve/galerkin_operator.hpp"
#include "cleave/solve/grid_level.hpp"
#include "cleave/solve/parallel_ranges.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/coarsest_factor.hpp"
#include "cleave/solve/sparse_multiply.hpp"
#include "cleave/solve/vertex_operator.hpp"

namespace cleave {
namespace {

constexpr std::size_t kVerticesPerTask = 1024;

}  // namespace

MultigridPreconditioner::MultigridPreconditioner() = default;
MultigridPreconditioner::~MultigridPreconditioner() = default;
MultigridPreconditioner::MultigridPreconditioner(MultigridPreconditioner&&) noexcept = default;
MultigridPreconditioner& MultigridPreconditioner::operator=(MultigridPreconditioner&&) noexcept = default;

namespace {

template <typename VectorType>
void prolongate_add_any(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const VectorType& coarse,
                        VectorType& fine) {
  using Scalar = typename VectorType::Scalar;
  const auto vertices = static_cast<std::size_t>(p.fine_count());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices, kVerticesPerTask), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t v = range.begin(); v < range.end(); ++v) {
      Eigen::Matrix<Scalar, 3, 1> sum = Eigen::Matrix<Scalar, 3, 1>::Zero();
      for (int e = p.fine_start[v]; e < p.fine_start[v + 1]; ++e) {
        const auto& entry = p.by_fine[static_cast<std::size_t>(e)];
        sum += static_cast<Scalar>(entry.weight) * coarse.template segment<3>(3 * static_cast<Eigen::Index>(entry.vertex));
      }
      for (int axis = 0; axis < 3; ++axis)
        if (!fine_fixed[3 * v + static_cast<std::size_t>(axis)]) fine[static_cast<Eigen::Index>(3 * v) + axis] += sum[axis];
    }
  });
}

template <typename VectorType>
void restrict_to_coarse_any(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const VectorType& fine,
                            VectorType& coarse) {
  using Scalar = typename VectorType::Scalar;
  const auto vertices = static_cast<std::size_t>(p.coarse_count());
  coarse.resize(static_cast<Eigen::Index>(3 * vertices));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices, kVerticesPerTask), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t v = range.begin(); v < range.end(); ++v) {
      Eigen::Matrix<Scalar, 3, 1> sum = Eigen::Matrix<Scalar, 3, 1>::Zero();
      for (int e = p.coarse_start[v]; e < p.coarse_start[v + 1]; ++e) {
        const auto& entry = p.by_coarse[static_cast<std::size_t>(e)];
        const auto f = static_cast<std::size_t>(entry.vertex);
        for (int axis = 0; axis < 3; ++axis)
          if (!fine_fixed[3 * f + static_cast<std::size_t>(axis)])
            sum[axis] += static_cast<Scalar>(entry.weight) * fine[static_cast<Eigen::Index>(3 * f) + axis];
      }
      coarse.template segment<3>(static_cast<Eigen::Index>(3 * v)) = sum;
    }
  });
}

}  // namespace

void prolongate_add(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Vector& coarse, Vector& fine) {
  prolongate_add_any(p, fine_fixed, coarse, fine);
}
void prolongate_add(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Eigen::VectorXf& coarse,
                    Eigen::VectorXf& fine) {
  prolongate_add_any(p, fine_fixed, coarse, fine);
}
void restrict_to_coarse(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Vector& fine, Vector& coarse) {
  restrict_to_coarse_any(p, fine_fixed, fine, coarse);
}
void restrict_to_coarse(const Prolongation& p, const std::vector<std::uint8_t>& fine_fixed, const Eigen::VectorXf& fine,
                        Eigen::VectorXf& coarse) {
  restrict_to_coarse_any(p, fine_fixed, fine, coarse);
}

namespace {

/// Writes `values` rounded to float into `single` (same length).
void round_to_single(const std::vector<double>& values, std::vector<float>& single) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, values.size(), std::size_t{1} << 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) single[i] = static_cast<float>(values[i]);
                    });
}

BlockSparseMatrix<float> single_precision_copy(const BlockSparseMatrix<double>& a) {
  BlockSparseMatrix<float> b;
  b.row_start = a.row_start;
  b.column = a.column;
  b.values.resize(a.values.size());
  round_to_single(a.values, b.values);
  return b;
}

/// by_coarse from by_fine (fine vertices ascending within each coarse vertex).
void transpose_prolongation(Prolongation& p) {
  const auto coarse = static_cast<std::size_t>(p.coarse_count());
  p.coarse_start.assign(coarse + 1, 0);
  for (const Prolongation::Entry& e : p.by_fine) ++p.coarse_start[static_cast<std::size_t>(e.vertex) + 1];
  for (std::size_t c = 0; c < coarse; ++c) p.coarse_start[c + 1] += p.coarse_start[c];
  p.by_coarse.resize(p.by_fine.size());
  std::vector<int> next(p.coarse_start.begin(), p.coarse_start.end() - 1);
  for (VertexId f = 0; f < p.fine_count(); ++f)
    for (int k = p.fine_start[static_cast<std::size_t>(f)]; k < p.fine_start[static_cast<std::size_t>(f) + 1]; ++k) {
      const Prolongation::Entry& e = p.by_fine[static_cast<std::size_t>(k)];
      p.by_coarse[static_cast<std::size_t>(next[static_cast<std::size_t>(e.vertex)]++)] = {f, e.weight};
    }
}

}  // namespace

MultigridPreconditioner build_multigrid(const SparseMatrix& a, const LinkedVolume& volume, const MultigridOptions& options) {
  if (!a.isCompressed()) throw InputError("multigrid: matrix must be compressed (makeCompressed)");
  if (a.rows() != a.cols())
    throw InputError(fmt::format("multigrid: matrix is {} x {}; expected a square matrix with 3 dofs per vertex", a.rows(), a.cols()));
  return build_multigrid(to_block_sparse<double>(a), volume, options);
}

MultigridPreconditioner build_levels(const BlockSparseMatrix<double>& a, const VertexOperator* fine_operator,
                                     const ChebyshevWarmStart& fine_warm, const LinkedVolume& volume, const MultigridOptions& options);

MultigridPreconditioner build_multigrid(const BlockSparseMatrix<double>& a, const LinkedVolume& volume, const MultigridOptions& options) {
  return build_levels(a, nullptr, {}, volume, options);
}

MultigridPreconditioner build_multigrid_for_operator(const VertexOperator& fine, const BlockSparseMatrix<double>& a,
                                                     const LinkedVolume& volume, const MultigridOptions& options,
                                                     const ChebyshevWarmStart& fine_warm) {
  if (fine.rows() != a.rows() || fine.fixed_dofs().size() != static_cast<std::size_t>(a.rows()))
    throw InputError(fmt::format("multigrid: the fine operator has {} rows and {} fixed flags; its assembled matrix has {} rows",
                                 fine.rows(), fine.fixed_dofs().size(), a.rows()));
  return build_levels(a, &fine, fine_warm, volume, options);
}

/// build_multigrid, with the fine level applied by `fine_operator` when it is given, its smoother's
/// estimate continued from `fine_warm` (see build_multigrid_for_operator).
MultigridPreconditioner build_levels(const BlockSparseMatrix<double>& a, const VertexOperator* fine_operator,
                                     const ChebyshevWarmStart& fine_warm, const LinkedVolume& volume, const MultigridOptions& options) {
  const auto dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  if (a.rows() != dofs)
    throw InputError(fmt::format("multigrid: matrix has {} rows; expected {} (3 dofs per vertex of the linked volume)", a.rows(), dofs));
  if (!(options.coarsest_factor_share >= 0 && options.coarsest_factor_share <= 1))
    throw InputError(fmt::format("multigrid: coarsest factor share is {}; expected a share from 0 to 1 of the fine matrix's entries",
                                 options.coarsest_factor_share));
  if (!(options.coarsest_factor_flops_per_fine_entry >= 0 && std::isfinite(options.coarsest_factor_flops_per_fine_entry)))
    throw InputError(fmt::format("multigrid: coarsest factor flops per fine entry is {}; expected a finite number of 0 or more",
                                 options.coarsest_factor_flops_per_fine_entry));
  if (options.coarse_degree < 1)
    throw InputError(fmt::format("multigrid: coarse smoother degree is {}; expected 1 or more", options.coarse_degree));
  if (options.smoother.degree < 1)
    throw InputError(fmt::format("multigrid: fine smoother degree is {}; expected 1 or more", options.smoother.degree));
  for (const double range : {options.smoother.smoothing_range, options.coarse_smoothing_range})
    if (!(range > 1 && std::isfinite(range)))
      throw InputError(fmt::format("multigrid: smoothing range is {}; expected a finite ratio above 1 (lambda_max over the lower "
                                   "end of the damped interval)", range));
  MultigridPreconditioner m;
  m.levels_.reserve(static_cast<std::size_t>(std::max(options.max_levels, 1)));  // no reallocation: it would copy the levels' matrices
  GridLevel grid = grid_level_of(volume);
  {
    MultigridLevel fine;
    fine.fixed = fine_operator != nullptr ? fine_operator->fixed_dofs() : identity_rows(a);
    m.levels_.push_back(std::move(fine));
  }
  m.coarsest_ = std::make_unique<CoarsestFactor>();
  // The coarsest level's matrix (ColMajor, as the factorizations take it), once chosen.
  Eigen::SparseMatrix<double> coarsest;
  std::optional<std::size_t> analyzed_level;  // the level `coarsest` holds and the factor has analyzed
  const auto fine_entries = static_cast<double>(a.values.size());
  const double factor_budget = options.coarsest_factor_share * fine_entries;
  while (static_cast<int>(m.levels_.size()) < options.max_levels) {
    const std::size_t l = m.levels_.size() - 1;
    // Free dofs only: held pieces (the removed plugs of round incisions) keep their replicas of
    // coarse cells down to the coarsest level, but cost its factorization nothing.
    const auto& fixed = m.levels_[l].fixed;
    const auto free_dofs = static_cast<std::ptrdiff_t>(fixed.size()) - std::count(fixed.begin(), fixed.end(), std::uint8_t{1});
    if (free_dofs <= options.coarsest_max_dofs) break;
    // A coarse level whose factor is cheap enough ends the hierarchy. A factor holds at least the
    // lower triangle, so a level with more than twice the budget's entries is not analyzed.
    if (l > 0 && static_cast<double>(m.levels_[l].matrix.nonZeros()) <= 2.0 * factor_budget) {
      coarsest = m.levels_[l].matrix;
      analyzed_level = l;
      const FactorCost cost = m.coarsest_->analyze(coarsest);
      if (cost.nonzeros <= factor_budget && cost.flops <= options.coarsest_factor_flops_per_fine_entry * fine_entries) break;
    }
    Coarsening next = coarsen_grid_level(grid);
    const double ratio = static_cast<double>(next.coarse.vertex_count) / static_cast<double>(grid.vertex_count);
    if (ratio > options.min_coarsening_ratio) break;
    // An operator's fine level has no rows to solve pieces with.
    if (l > 0 || fine_operator == nullptr) m.levels_[l].weak_pieces = find_weak_pieces(grid, options.weak_pieces);
    // Built in place: Eigen 3.4's SparseMatrix has no move, so assigning or moving one copies it.
    SparseMatrix galerkin = l == 0 ? galerkin_operator(a, m.levels_[l].fixed, next.prolongation)
                                   : galerkin_operator(m.levels_[l].matrix, m.levels_[l].fixed, next.prolongation);
    m.levels_[l].from_coarser = std::move(next.prolongation);
    grid = std::move(next.coarse);
    MultigridLevel& coarse = m.levels_.emplace_back();
    coarse.matrix.swap(galerkin);
    coarse.fixed = identity_rows(coarse.matrix);
  }
  m.precision_ = options.precision;
  const bool apply_fine_operator = fine_operator != nullptr && m.levels_.size() > 1;
  for (std::size_t l = 0; l + 1 < m.levels_.size(); ++l) {
    MultigridLevel& level = m.levels_[l];
    ChebyshevOptions smoother = options.smoother;
    if (l > 0) {
      smoother.degree = options.coarse_degree;
      smoother.smoothing_range = options.coarse_smoothing_range;
    }
    if (l == 0 && apply_fine_operator) {
      m.fine_operator_ = fine_operator;
      level.smoother =
          m.precision_ == CyclePrecision::single_precision
              ? make_chebyshev_smoother<float>(*fine_operator, fine_operator->inverse_diagonal_blocks(), smoother, fine_warm)
              : make_chebyshev_smoother<double>(*fine_operator, fine_operator->inverse_diagonal_blocks(), smoother, fine_warm);
      continue;
    }
    if (m.precision_ == CyclePrecision::single_precision) {
      level.single.blocks = l == 0 ? single_precision_copy(a) : to_block_sparse<float>(level.matrix);
      level.smoother = make_chebyshev_smoother(level.single.blocks, smoother);
    } else {
      level.twin.blocks = l == 0 ? a : to_block_sparse<double>(level.matrix);
      level.smoother = make_chebyshev_smoother(level.twin.blocks, smoother);
    }
    // The pieces are inverted in double: from the fine matrix, the double cycle's blocks, or (a
    // float cycle's coarse level with pieces) a double block copy made for it.
    if (l == 0) level.weak_pieces.factor(a, level.fixed);
    else if (m.precision_ == CyclePrecision::double_precision) level.weak_pieces.factor(level.twin.blocks, level.fixed);
    else if (level.weak_pieces.piece_count() > 0) level.weak_pieces.factor(to_block_sparse<double>(level.matrix), level.fixed);
  }

  const std::size_t last = m.levels_.size() - 1;
  if (analyzed_level != last) {
    coarsest = last == 0 ? Eigen::SparseMatrix<double>(to_scalar_sparse(a)) : Eigen::SparseMatrix<double>(m.levels_[last].matrix);
    m.coarsest_->analyze(coarsest);
  }
  m.coarsest_->factorize(coarsest);
  if (m.precision_ == CyclePrecision::single_precision) m.allocate_cycle<float>();
  else m.allocate_cycle<double>();
  return m;
}

template <typename Scalar>
void MultigridPreconditioner::allocate_cycle() {
  for (auto& level : levels_) {
    const auto n = static_cast<Eigen::Index>(level.fixed.size());
    const CycleData<Scalar>& data = level.data<Scalar>();
    data.rhs.setZero(n);
    data.solution.setZero(n);
    data.residual.setZero(n);
  }
}

void MultigridPreconditioner::use_double_precision(const BlockSparseMatrix<double>& fine) {
  if (precision_ == CyclePrecision::double_precision) return;
  precision_ = CyclePrecision::double_precision;
  for (std::size_t l = 0; l + 1 < levels_.size(); ++l) {
    levels_[l].single = CycleData<float>();
    levels_[l].twin.blocks = l == 0 ? fine : to_block_sparse<double>(levels_[l].matrix);
  }
  if (levels_.size() > 1 && fine_operator_ == nullptr) levels_[0].smoother.set_inverse_diagonal(inverse_diagonal_blocks(fine));
  allocate_cycle<double>();
}

void MultigridPreconditioner::refresh_fine_level(const BlockSparseMatrix<double>& a) {
  if (levels_.size() < 2) return;  // a single level: the (older) factorization preconditions
  MultigridLevel& fine = levels_[0];
  fine_operator_ = nullptr;
  if (a.row_start.size() != fine.smoother.inverse_diagonal.size() + 1 ||
      a.blocks() != (precision_ == CyclePrecision::single_precision ? fine.single.blocks.blocks() : fine.twin.blocks.blocks()))
    throw InputError("multigrid: the refreshed matrix does not have the pattern the levels were built from");
  fine.smoother.set_inverse_diagonal(inverse_diagonal_blocks(a));
  fine.weak_pieces.factor(a, fine.fixed);
  if (precision_ == CyclePrecision::double_precision) {
    fine.twin.blocks.values = a.values;
    return;
  }
  round_to_single(a.values, fine.single.blocks.values);
}

void MultigridPreconditioner::extend_fine_prolongation(const std::vector<VertexId>& origin_of_new, Eigen::Index new_rows) {
  if (levels_.size() < 2) throw InputError("multigrid: a single-level hierarchy has no fine level to replace; set it up afresh");
  Prolongation& p = levels_[0].from_coarser;
  const VertexId old_count = p.fine_count();
  const auto copies = static_cast<VertexId>(origin_of_new.size());
  if (new_rows != 3 * static_cast<Eigen::Index>(old_count + copies))
    throw InputError(fmt::format("multigrid: the new fine matrix has {} rows; expected {} ({} vertices and {} copies, 3 dofs each)",
                                 new_rows, 3 * (old_count + copies), old_count, copies));
  for (const VertexId origin : origin_of_new)
    if (origin < 0 || origin >= old_count)
      throw InputError(fmt::format("multigrid: a divided vertex's origin is {}; expected a vertex of the old fine level (0 to {})",
                                   origin, old_count - 1));
  p.by_fine.reserve(p.by_fine.size() + 8 * origin_of_new.size());
  for (const VertexId origin : origin_of_new) {
    for (int k = p.fine_start[static_cast<std::size_t>(origin)]; k < p.fine_start[static_cast<std::size_t>(origin) + 1]; ++k) {
      const Prolongation::Entry entry = p.by_fine[static_cast<std::size_t>(k)];
      p.by_fine.push_back(entry);
    }
    p.fine_start.push_back(static_cast<int>(p.by_fine.size()));
  }
  transpose_prolongation(p);
}

void MultigridPreconditioner::replace_fine_level(const VertexOperator& a, std::vector<Mat3> inverse_diagonal,
                                                 const std::vector<VertexId>& origin_of_new, const ChebyshevOptions& smoother) {
  if (inverse_diagonal.size() != static_cast<std::size_t>(a.rows() / 3) || a.fixed_dofs().size() != static_cast<std::size_t>(a.rows()))
    throw InputError(fmt::format("multigrid: the new fine operator has {} rows, {} diagonal blocks and {} fixed flags",
                                 a.rows(), inverse_diagonal.size(), a.fixed_dofs().size()));
  extend_fine_prolongation(origin_of_new, a.rows());
  MultigridLevel& fine = levels_[0];
  fine_operator_ = &a;
  fine.fixed = a.fixed_dofs();
  fine.weak_pieces = WeakPieceSolves();  // found on the old cells; the next rebuild finds the new ones
  fine.single.blocks = BlockSparseMatrix<float>();  // the old pattern: of no use to the new level
  fine.twin.blocks = BlockSparseMatrix<double>();
  const ChebyshevSmoother before = std::move(fine.smoother);
  const ChebyshevWarmStart warm{&before, &origin_of_new};
  if (precision_ == CyclePrecision::single_precision) {
    fine.smoother = make_chebyshev_smoother<float>(a, std::move(inverse_diagonal), smoother, warm);
    allocate_cycle<float>();
  } else {
    fine.smoother = make_chebyshev_smoother<double>(a, std::move(inverse_diagonal), smoother, warm);
    allocate_cycle<double>();
  }
}

void MultigridPreconditioner::replace_fine_level(const BlockSparseMatrix<double>& a, const std::vector<VertexId>& origin_of_new,
                                                 const ChebyshevOptions& smoother) {
  extend_fine_prolongation(origin_of_new, a.rows());
  MultigridLevel& fine = levels_[0];
  fine_operator_ = nullptr;
  fine.fixed = identity_rows(a);
  fine.weak_pieces = WeakPieceSolves();  // found on the old cells; the next rebuild finds the new ones
  const ChebyshevSmoother before = std::move(fine.smoother);
  const ChebyshevWarmStart warm{&before, &origin_of_new};
  if (precision_ == CyclePrecision::single_precision) {
    fine.single.blocks = single_precision_copy(a);
    fine.smoother = make_chebyshev_smoother(fine.single.blocks, smoother, warm);
    allocate_cycle<float>();
  } else {
    fine.twin.blocks = a;
    fine.smoother = make_chebyshev_smoother(fine.twin.blocks, smoother, warm);
    allocate_cycle<double>();
  }
}

const SparseMatrix& MultigridPreconditioner::coarse_operator(std::size_t level) const {
  if (level == 0 || level >= levels_.size())
    throw InputError(fmt::format("multigrid: level {} has no coarse operator; expected 1 to {}", level, levels_.size() - 1));
  return levels_[level].matrix;
}

void MultigridPreconditioner::use_fine_operator(const VertexOperator& a, std::vector<Mat3> inverse_diagonal) {
  if (levels_.size() < 2) return;  // a single level: the (older) factorization preconditions
  if (a.rows() != static_cast<Eigen::Index>(levels_[0].fixed.size()) ||
      inverse_diagonal.size() != levels_[0].smoother.inverse_diagonal.size())
    throw InputError(fmt::format("multigrid: the fine operator has {} rows and {} diagonal blocks; the fine level has {} dofs",
                                 a.rows(), inverse_diagonal.size(), levels_[0].fixed.size()));
  fine_operator_ = &a;
  levels_[0].smoother.set_inverse_diagonal(std::move(inverse_diagonal));
}

template <typename Scalar>
void MultigridPreconditioner::cycle(std::size_t l) const {
  const MultigridLevel& level = levels_[l];
  const CycleData<Scalar>& data = level.data<Scalar>();
  if (l + 1 == levels_.size()) {
    const Vector rhs = data.rhs.template cast<double>();
    data.solution = coarsest_->solve(rhs).template cast<Scalar>();
    if (!data.solution.allFinite()) data.solution.setZero();
    return;
  }
  if (l == 0 && fine_operator_ != nullptr) smooth_around_coarse_correction<Scalar>(l, *fine_operator_);
  else smooth_around_coarse_correction<Scalar>(l, data.blocks);
}

template <typename Scalar, typename Matrix>
void MultigridPreconditioner::smooth_around_coarse_correction(std::size_t l, const Matrix& a) const {
  const MultigridLevel& level = levels_[l];
  const CycleData<Scalar>& data = level.data<Scalar>();
  // Weak pieces need the rows of A (block CSR); a fine level applied without its matrix has none.
  constexpr bool kHasRows = std::is_same_v<Matrix, BlockSparseMatrix<Scalar>>;
  level.smoother.smooth_from_zero(a, data.rhs, data.solution, data.work);
  if constexpr (kHasRows) level.weak_pieces.correct(a, data.rhs, data.solution, SweepOrder::forward);
  residual(a, data.rhs, data.solution, data.residual);
  const CycleData<Scalar>& coarse = levels_[l + 1].data<Scalar>();
  restrict_to_coarse(level.from_coarser, level.fixed, data.residual, coarse.rhs);
  cycle<Scalar>(l + 1);
  prolongate_add(level.from_coarser, level.fixed, coarse.solution, data.solution);
  if constexpr (kHasRows) level.weak_pieces.correct(a, data.rhs, data.solution, SweepOrder::backward);
  level.smoother.smooth(a, data.rhs, data.solution, data.work);
}

void MultigridPreconditioner::apply(const Vector& r, Vector& z) const {
  if (precision_ == CyclePrecision::single_precision) {
    cast_in_parallel(r, levels_[0].single.rhs);
    cycle<float>(0);
    cast_in_parallel(levels_[0].single.solution, z);
  } else {
    levels_[0].twin.rhs = r;
    cycle<double>(0);
    z = levels_[0].twin.solution;
  }
}

}  // namespace cleave
