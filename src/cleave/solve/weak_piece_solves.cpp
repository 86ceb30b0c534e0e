#include "cleave/solve/weak_piece_solves.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

/// Per cell: the cells it is linked to (each link seen from both sides).
std::vector<std::vector<CellId>> linked_cells(const GridLevel& grid) {
  std::vector<std::vector<CellId>> neighbours(static_cast<std::size_t>(grid.cell_count()));
  for (const LevelLink& link : grid.links) {
    neighbours[static_cast<std::size_t>(link.from)].push_back(link.to);
    neighbours[static_cast<std::size_t>(link.to)].push_back(link.from);
  }
  return neighbours;
}

/// Position of `v` in the sorted `vertices`, or -1.
int local_index(const std::vector<VertexId>& vertices, VertexId v) {
  const auto it = std::lower_bound(vertices.begin(), vertices.end(), v);
  return it != vertices.end() && *it == v ? static_cast<int>(it - vertices.begin()) : -1;
}

/// Greedy colouring of the pieces: piece p conflicts with piece q when one of p's rows reads a
/// dof q writes (`reads[p]`: the column vertices of p's rows; q writes its own vertices). Pieces
/// of one colour can then be solved at the same time.
void colour_by_conflicts(VertexId vertex_count, const std::vector<int>& piece_start, const std::vector<VertexId>& vertex,
                   const std::vector<std::vector<VertexId>>& reads, std::vector<int>& colour_start, std::vector<int>& by_colour) {
  const auto pieces = piece_start.size() - 1;
  std::vector<std::vector<int>> writers(static_cast<std::size_t>(vertex_count));
  for (std::size_t p = 0; p < pieces; ++p)
    for (auto k = static_cast<std::size_t>(piece_start[p]); k < static_cast<std::size_t>(piece_start[p + 1]); ++k)
      writers[static_cast<std::size_t>(vertex[k])].push_back(static_cast<int>(p));
  std::vector<std::vector<int>> conflicts(pieces);
  for (std::size_t p = 0; p < pieces; ++p)
    for (const VertexId v : reads[p])
      for (const int q : writers[static_cast<std::size_t>(v)])
        if (q != static_cast<int>(p)) {
          conflicts[p].push_back(q);
          conflicts[static_cast<std::size_t>(q)].push_back(static_cast<int>(p));
        }
  std::vector<int> colour(pieces, -1);
  int colours = 0;
  std::vector<std::uint8_t> used;
  for (std::size_t p = 0; p < pieces; ++p) {
    used.assign(static_cast<std::size_t>(colours) + 1, 0);
    for (const int q : conflicts[p])
      if (colour[static_cast<std::size_t>(q)] >= 0) used[static_cast<std::size_t>(colour[static_cast<std::size_t>(q)])] = 1;
    const auto first_free = std::find(used.begin(), used.end(), std::uint8_t{0}) - used.begin();
    colour[p] = static_cast<int>(first_free);
    colours = std::max(colours, colour[p] + 1);
  }
  colour_start.assign(static_cast<std::size_t>(colours) + 1, 0);
  for (const int c : colour) ++colour_start[static_cast<std::size_t>(c) + 1];
  for (std::size_t c = 0; c < static_cast<std::size_t>(colours); ++c) colour_start[c + 1] += colour_start[c];
  by_colour.assign(pieces, 0);
  std::vector<int> next(colour_start.begin(), colour_start.end() - 1);
  for (std::size_t p = 0; p < pieces; ++p) by_colour[static_cast<std::size_t>(next[static_cast<std::size_t>(colour[p])]++)] = static_cast<int>(p);
}

}  // namespace

WeakPieceSolves find_weak_pieces(const GridLevel& grid, const WeakPieceOptions& options) {
  WeakPieceSolves pieces;
  pieces.level_vertices_ = grid.vertex_count;
  if (options.max_links <= 0 || options.max_cells <= 0) return pieces;
  const auto cells = static_cast<std::size_t>(grid.cell_count());
  const std::vector<std::vector<CellId>> neighbours = linked_cells(grid);
  std::vector<std::uint8_t> weak(cells, 0);
  std::vector<std::uint8_t> faces(cells, 0);
  for (const LevelLink& link : grid.links) {
    faces[static_cast<std::size_t>(link.from)] |= static_cast<std::uint8_t>(1u << link.face);
    faces[static_cast<std::size_t>(link.to)] |= static_cast<std::uint8_t>(1u << opposite(link.face));
  }
  for (std::size_t c = 0; c < cells; ++c) {
    const int links = static_cast<int>(neighbours[c].size());
    const std::uint8_t f = faces[c];
    const bool opposite_pair = (f & 0b000011u) == 0b000011u || (f & 0b001100u) == 0b001100u || (f & 0b110000u) == 0b110000u;
    weak[c] = links <= options.max_links && (links <= 2 || opposite_pair) ? 1 : 0;
  }
  std::vector<std::uint8_t> taken(cells, 0);
  std::vector<CellId> queue;
  std::vector<VertexId> vertices;
  for (std::size_t seed = 0; seed < cells; ++seed) {
    if (!weak[seed] || taken[seed]) continue;
    // Breadth first over weak cells through links, until the piece is full.
    queue.assign(1, static_cast<CellId>(seed));
    taken[seed] = 1;
    for (std::size_t head = 0; head < queue.size() && static_cast<int>(queue.size()) < options.max_cells; ++head)
      for (const CellId next : neighbours[static_cast<std::size_t>(queue[head])]) {
        const auto n = static_cast<std::size_t>(next);
        if (!weak[n] || taken[n] || static_cast<int>(queue.size()) >= options.max_cells) continue;
        taken[n] = 1;
        queue.push_back(next);
      }
    vertices.clear();
    for (const CellId c : queue)
      for (const VertexId v : grid.cell_vertices[static_cast<std::size_t>(c)]) vertices.push_back(v);
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    pieces.vertex_.insert(pieces.vertex_.end(), vertices.begin(), vertices.end());
    pieces.piece_start_.push_back(static_cast<int>(pieces.vertex_.size()));
  }
  return pieces;
}

std::vector<VertexId> WeakPieceSolves::piece_vertices(int p) const {
  return {vertex_.begin() + piece_start_[static_cast<std::size_t>(p)], vertex_.begin() + piece_start_[static_cast<std::size_t>(p) + 1]};
}

void WeakPieceSolves::factor(const BlockSparseMatrix<double>& a, const std::vector<std::uint8_t>& fixed) {
  if (a.rows() != 3 * static_cast<Eigen::Index>(level_vertices_) || fixed.size() != static_cast<std::size_t>(a.rows()))
    throw InputError(fmt::format("weak pieces: matrix of {} rows and {} fixed flags for a level of {} vertices; expected {} each",
                                 a.rows(), fixed.size(), level_vertices_, 3 * static_cast<Eigen::Index>(level_vertices_)));
  const auto row_blocks = [&](VertexId v) {
    return std::pair{static_cast<std::size_t>(a.row_start[static_cast<std::size_t>(v)]),
                     static_cast<std::size_t>(a.row_start[static_cast<std::size_t>(v) + 1])};
  };
  // Room for the inverse of every piece with a free dof (a piece of held dofs only, a removed
  // plug, has nothing to solve), then the pieces in parallel, each into its own place.
  const auto pieces = static_cast<std::size_t>(piece_count());
  inverse_start_.assign(pieces, -1);
  std::int64_t size = 0;
  std::vector<std::vector<VertexId>> reads(pieces);  // the column vertices of each piece's rows
  for (std::size_t p = 0; p < pieces; ++p) {
    const auto first = static_cast<std::size_t>(piece_start_[p]), last = static_cast<std::size_t>(piece_start_[p + 1]);
    for (std::size_t i = first; i < last; ++i) {
      const auto [k0, k1] = row_blocks(vertex_[i]);
      reads[p].insert(reads[p].end(), a.column.begin() + static_cast<std::ptrdiff_t>(k0), a.column.begin() + static_cast<std::ptrdiff_t>(k1));
    }
    std::sort(reads[p].begin(), reads[p].end());
    reads[p].erase(std::unique(reads[p].begin(), reads[p].end()), reads[p].end());
    bool any_free = false;
    for (std::size_t i = first; i < last && !any_free; ++i)
      for (std::size_t axis = 0; axis < 3; ++axis) any_free = any_free || !fixed[3 * static_cast<std::size_t>(vertex_[i]) + axis];
    if (!any_free) continue;
    inverse_start_[p] = size;
    size += 9 * static_cast<std::int64_t>((last - first) * (last - first));
  }
  colour_by_conflicts(level_vertices_, piece_start_, vertex_, reads, colour_start_, by_colour_);
  inverse_.assign(static_cast<std::size_t>(size), 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pieces, 4), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t p = range.begin(); p < range.end(); ++p) {
      if (inverse_start_[p] < 0) continue;
      const std::vector<VertexId> vertices = piece_vertices(static_cast<int>(p));
      const auto n = static_cast<Eigen::Index>(3 * vertices.size());
      Eigen::MatrixXd block = Eigen::MatrixXd::Zero(n, n);
      for (std::size_t i = 0; i < vertices.size(); ++i) {
        const auto [k0, k1] = row_blocks(vertices[i]);
        for (std::size_t k = k0; k < k1; ++k) {
          const int j = local_index(vertices, a.column[k]);
          if (j >= 0)
            block.block<3, 3>(3 * static_cast<Eigen::Index>(i), 3 * j) =
                Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(a.values.data() + 9 * k);
        }
      }
      // Held dofs: identity rows and columns for the factorization, zero in the inverse, so the
      // piece's solve leaves them where they are.
      std::vector<Eigen::Index> held;
      for (Eigen::Index d = 0; d < n; ++d) {
        const VertexId v = vertices[static_cast<std::size_t>(d / 3)];
        if (!fixed[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(d % 3)]) continue;
        held.push_back(d);
        block.row(d).setZero();
        block.col(d).setZero();
        block(d, d) = 1;
      }
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(block);
      if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.vectorD().minCoeff() > 0)) {
        inverse_start_[p] = -1;  // its room stays unused
        continue;
      }
      Eigen::Map<Eigen::MatrixXd> inverse(inverse_.data() + inverse_start_[p], n, n);
      inverse = ldlt.solve(Eigen::MatrixXd::Identity(n, n));
      for (const Eigen::Index d : held) {
        inverse.row(d).setZero();
        inverse.col(d).setZero();
      }
    }
  });
  factored_ = static_cast<int>(std::count_if(inverse_start_.begin(), inverse_start_.end(), [](std::int64_t start) { return start >= 0; }));
}

template <typename Scalar>
void WeakPieceSolves::correct(const BlockSparseMatrix<Scalar>& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                              Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, SweepOrder order) const {
  if (empty()) return;
  const auto solve_piece = [&](std::size_t p, Eigen::VectorXd& residual, Eigen::VectorXd& step) {
    if (inverse_start_[p] < 0) return;
    const auto first = static_cast<std::size_t>(piece_start_[p]), last = static_cast<std::size_t>(piece_start_[p + 1]);
    const auto n = static_cast<Eigen::Index>(3 * (last - first));
    residual.resize(n);
    for (std::size_t i = first; i < last; ++i) {
      const auto v = static_cast<std::size_t>(vertex_[i]);
      Eigen::Matrix<Scalar, 3, 1> sum = b.template segment<3>(static_cast<Eigen::Index>(3 * v));
      for (auto k = static_cast<std::size_t>(a.row_start[v]); k < static_cast<std::size_t>(a.row_start[v + 1]); ++k)
        sum.noalias() -= Eigen::Map<const Eigen::Matrix<Scalar, 3, 3, Eigen::RowMajor>>(a.values.data() + 9 * k) *
                         x.template segment<3>(3 * static_cast<Eigen::Index>(a.column[k]));
      residual.segment<3>(static_cast<Eigen::Index>(3 * (i - first))) = sum.template cast<double>();
    }
    step.noalias() = Eigen::Map<const Eigen::MatrixXd>(inverse_.data() + inverse_start_[p], n, n) * residual;  // held dofs: 0
    for (std::size_t i = first; i < last; ++i)
      x.template segment<3>(3 * static_cast<Eigen::Index>(vertex_[i])) +=
          step.segment<3>(static_cast<Eigen::Index>(3 * (i - first))).template cast<Scalar>();
  };
  const auto colours = colour_start_.size() - 1;
  for (std::size_t s = 0; s < colours; ++s) {
    const std::size_t c = order == SweepOrder::forward ? s : colours - 1 - s;
    tbb::parallel_for(tbb::blocked_range<int>(colour_start_[c], colour_start_[c + 1], 16), [&](const tbb::blocked_range<int>& range) {
      Eigen::VectorXd residual, step;  // per task, reused across its pieces
      for (int k = range.begin(); k < range.end(); ++k)
        solve_piece(static_cast<std::size_t>(by_colour_[static_cast<std::size_t>(k)]), residual, step);
    });
  }
}

template void WeakPieceSolves::correct<float>(const BlockSparseMatrix<float>&, const Eigen::VectorXf&, Eigen::VectorXf&, SweepOrder) const;
template void WeakPieceSolves::correct<double>(const BlockSparseMatrix<double>&, const Eigen::VectorXd&, Eigen::VectorXd&,
                                               SweepOrder) const;

}  // namespace cleave
