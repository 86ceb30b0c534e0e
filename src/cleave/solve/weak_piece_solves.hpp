#pragma once
// Exact local solves on the weakly linked pieces of one multigrid level: cells held to the rest
// by at most two uncut links, or three of which two are opposite (a column of cells left standing
// where a round incision meets the body's edge, a sliver a cut leaves), grouped by their links.
// Such a piece is a thin beam or hinge whose bending modes have almost no energy: the
// block-Jacobi Chebyshev smoother cannot damp them (their eigenvalues of D^-1 A are tiny) and the
// trilinear coarse space cannot represent them (the piece and the body it hangs on share a coarse cell). On the 44k-cell
// incised tube one such column made the V-cycle's worst error mode (A-norm reduction 0.93 per
// cycle); each piece's dofs are therefore solved exactly, Gauss-Seidel fashion over the pieces
// (pieces that do not read each other's dofs in parallel), between the smoother and the coarse
// correction.
//
//   WeakPieceSolves pieces = find_weak_pieces(grid, {});   // on the level's cells and links
//   pieces.factor(a, fixed);                               // the inverse of each piece's block
//   pieces.correct(a, b, x, SweepOrder::forward);          // x += A_p^-1 (b - A x)_p per piece
//   ...coarse correction...
//   pieces.correct(a, b, x, SweepOrder::backward);         // the reverse sweep keeps the cycle symmetric
//
// A piece holds the free dofs of every vertex of its cells (those it shares with the body
// included: a local Dirichlet problem). Pieces larger than `max_cells` are split, so a long
// chain stays a row of small dense solves. A piece whose block is not positive definite (it
// cannot be, for an SPD matrix, unless rounding hides a mechanism) is left out.
#include <Eigen/Cholesky>
#include <cstdint>
#include <vector>

#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/grid_level.hpp"

namespace cleave {

struct WeakPieceOptions {
  /// Cells with this many uncut links or fewer are weak (a cell inside a solid body has 6, on a
  /// flat face 5, an edge 4, a corner 3), except that a cell with three links is weak only when
  /// two of them are opposite (a cell of a column or ledge two cells wide), not when it has one
  /// per axis (a corner of a staircase surface: held in every direction). 0: no pieces.
  /// The preview's iterations on the incised tube at 42 / 60 / 84 cells across: 29 / 37 / 50
  /// without pieces; 16 / 18 / 27 with the cells of at most 2 links; 15 / 17 / 17 with this rule
  /// (124 / 120 / 184 pieces on the fine level); 15 / 16 / 16 with every cell of 3 links (569 /
  /// 908 / 1470 pieces, and 2,920 on the incised abdomen-126 whose staircase shell gains nothing
  /// from them: 31 iterations against 32, at 1.4-1.8x the time). The uncut tube needs 12.
  int max_links = 3;
  /// Cells per piece at most: its inverse has (3 x its vertices)^2 entries, read at every sweep.
  /// 8 and 24 give the same iterations on the incised tube; 8 keeps the inverses 30 % smaller on
  /// the incised abdomen (7 MB against 10 MB at 45k cells).
  int max_cells = 8;
};

enum class SweepOrder { forward, backward };

class WeakPieceSolves {
 public:
  /// True when there is nothing to solve (no pieces, or none factored yet).
  bool empty() const { return factored_ == 0; }
  int piece_count() const { return static_cast<int>(piece_start_.size()) - 1; }
  int factored_count() const { return factored_; }
  /// Bytes of the pieces' inverses.
  std::size_t inverse_bytes() const { return inverse_.size() * sizeof(double); }
  /// Vertices of piece p (sorted).
  std::vector<VertexId> piece_vertices(int p) const;
  /// Colours of the parallel sweep (set by factor): no piece of a colour reads a dof (a column of
  /// its rows) that another piece of the colour writes (its own vertices).
  int colour_count() const { return static_cast<int>(colour_start_.size()) - 1; }
  std::vector<int> colour_pieces(int c) const {
    return {by_colour_.begin() + colour_start_[static_cast<std::size_t>(c)], by_colour_.begin() + colour_start_[static_cast<std::size_t>(c) + 1]};
  }

  /// Inverts each piece's block of `a` (its rows and columns; block CSR on the level's vertices;
  /// by LDL^T, kept as the explicit inverse: pieces are small, and one dense product per solve
  /// is faster than two triangular solves), with the dofs `fixed` flags as held. Throws
  /// InputError when `a` or `fixed` do not have the level's size. Pieces whose block is not
  /// positive definite are dropped.
  void factor(const BlockSparseMatrix<double>& a, const std::vector<std::uint8_t>& fixed);

  /// For each piece in turn: x_p += A_p^-1 (b - A x)_p on its free dofs, with the residual of
  /// the piece's rows computed afresh (so a later piece sees what an earlier one moved).
  template <typename Scalar>
  void correct(const BlockSparseMatrix<Scalar>& a, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
               Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, SweepOrder order) const;

 private:
  friend WeakPieceSolves find_weak_pieces(const GridLevel& grid, const WeakPieceOptions& options);
  VertexId level_vertices_ = 0;
  std::vector<int> piece_start_{0};   ///< piece p's vertices: vertex_[piece_start_[p] .. piece_start_[p + 1])
  std::vector<VertexId> vertex_;
  /// Pieces by colour (from the matrix's pattern at factor): no piece of a colour reads what
  /// another writes, so a colour's pieces are solved in parallel.
  std::vector<int> colour_start_{0};  ///< colour c's pieces: by_colour_[colour_start_[c] .. colour_start_[c + 1])
  std::vector<int> by_colour_;
  /// Per piece: where its inverse starts in inverse_ (an n x n column-major block, n = 3 x its
  /// vertices, rows and columns of held dofs zero), -1 when left out.
  std::vector<std::int64_t> inverse_start_;
  std::vector<double> inverse_;
  int factored_ = 0;
};

/// The weak cells of `grid` grouped by their uncut links into pieces of at most
/// options.max_cells cells (breadth first from the piece's lowest cell). Not factored yet.
WeakPieceSolves find_weak_pieces(const GridLevel& grid, const WeakPieceOptions& options);

}  // namespace cleave
