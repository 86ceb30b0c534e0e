// The weakly linked pieces of a multigrid level (columns of cells held by one or two faces) and
// their exact local solves inside the V-cycle.
#include "cleave/solve/weak_piece_solves.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "cleave/core/error.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/solve/galerkin_operator.hpp"
#include "cleave/solve/multigrid_cg_solver.hpp"
#include "cleave/solve/multigrid_preconditioner.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

/// A plate of `plate` cells (edge h_mm) with one-cell columns of `column_cells` cells standing on
/// its top face at the given (x, y) voxels: slender pieces, each cell of a column linked to the
/// cells above and below it only (the top one to one cell).
TissueModel make_plate_with_columns(const Vec3i& plate, int column_cells, const std::vector<Eigen::Vector2i>& columns, double h_mm) {
  LabelVolume labels;
  labels.grid.dims = plate + Vec3i(0, 0, column_cells);
  labels.grid.cell_size_mm = h_mm;
  labels.grid.origin_mm = Vec3::Zero();
  labels.labels.assign(static_cast<std::size_t>(labels.grid.voxel_count()), Label{0});
  const auto at = [&](int x, int y, int z) -> Label& {
    return labels.labels[static_cast<std::size_t>((z * labels.grid.dims.y() + y) * labels.grid.dims.x() + x)];
  };
  for (int z = 0; z < plate.z(); ++z)
    for (int y = 0; y < plate.y(); ++y)
      for (int x = 0; x < plate.x(); ++x) at(x, y, z) = 1;
  for (const Eigen::Vector2i& c : columns)
    for (int z = plate.z(); z < plate.z() + column_cells; ++z) at(c.x(), c.y(), z) = 1;
  Material m;
  m.youngs_modulus_kPa = test::kTissueE_kPa;
  m.poisson_ratio = test::kTissueNu;
  return make_tissue_model("plate with columns", std::move(labels), {{Label{1}, m}});
}

TEST(WeakPieces, AreTheColumnsCellsSplitIntoPiecesOfAtMostMaxCells) {
  const TissueModel model = make_plate_with_columns({8, 6, 2}, 7, {Eigen::Vector2i(2, 2), Eigen::Vector2i(5, 3)}, 2.0);
  const GridLevel grid = grid_level_of(model.volume);
  // Plate cells have 3 links or more (a corner cell of a 2-cell-thick plate: 3); column cells 2,
  // the top ones 1.
  const WeakPieceSolves whole = find_weak_pieces(grid, {.max_links = 2, .max_cells = 24});
  ASSERT_EQ(whole.piece_count(), 2);
  for (int p = 0; p < 2; ++p) EXPECT_EQ(whole.piece_vertices(p).size(), 4u * 8u);  // 7 cells stacked: 8 layers of 4 corners
  const WeakPieceSolves split = find_weak_pieces(grid, {.max_links = 2, .max_cells = 3});
  ASSERT_EQ(split.piece_count(), 6);  // 3 + 3 + 1 cells per column
  std::vector<std::size_t> sizes;
  for (int p = 0; p < split.piece_count(); ++p) sizes.push_back(split.piece_vertices(p).size());
  std::sort(sizes.begin(), sizes.end());
  EXPECT_EQ(sizes, (std::vector<std::size_t>{8, 8, 16, 16, 16, 16}));
  EXPECT_EQ(find_weak_pieces(grid, {.max_links = 1, .max_cells = 24}).piece_count(), 2);  // the top cells only
  EXPECT_EQ(find_weak_pieces(grid, {.max_links = 0, .max_cells = 24}).piece_count(), 0);
}

// A cell with three links is weak when two of them are opposite (a column two cells wide: up,
// down and its twin), not when it has one per axis (a box's corner: held in every direction).
TEST(WeakPieces, ThreeLinksMakeACellWeakOnlyWithAnOppositePair) {
  const TissueModel twin_columns = make_plate_with_columns({8, 6, 2}, 5, {Eigen::Vector2i(3, 2), Eigen::Vector2i(4, 2)}, 2.0);
  const GridLevel grid = grid_level_of(twin_columns.volume);
  const WeakPieceSolves tops = find_weak_pieces(grid, {.max_links = 2, .max_cells = 24});
  ASSERT_EQ(tops.piece_count(), 1);  // the two top cells: down and the twin
  EXPECT_EQ(tops.piece_vertices(0).size(), 12u);
  const WeakPieceSolves pieces = find_weak_pieces(grid, {.max_links = 3, .max_cells = 24});
  ASSERT_EQ(pieces.piece_count(), 1);
  EXPECT_EQ(pieces.piece_vertices(0).size(), 6u * 6u);  // 2 x 5 cells: 6 layers of 6 corners
  const TissueModel box = test::make_box({4, 4, 4}, 2.0);  // 8 corner cells of 3 links each
  EXPECT_EQ(find_weak_pieces(grid_level_of(box.volume), {.max_links = 3, .max_cells = 24}).piece_count(), 0);
}

TEST(WeakPieces, ACorrectionSolvesThePiecesRowsExactlyAndLeavesHeldDofs) {
  const TissueModel model = make_plate_with_columns({6, 6, 2}, 5, {Eigen::Vector2i(3, 3)}, 2.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const BlockSparseMatrix<double> a = to_block_sparse<double>(s.a);
  std::vector<std::uint8_t> fixed = identity_rows(a);
  WeakPieceSolves pieces = find_weak_pieces(grid_level_of(model.volume), {.max_links = 2, .max_cells = 24});
  pieces.factor(a, fixed);
  ASSERT_EQ(pieces.factored_count(), 1);
  const std::vector<VertexId> vertices = pieces.piece_vertices(0);
  Vector x = Vector::Constant(s.b.size(), 0.01);
  const Vector before = x;
  pieces.correct(a, s.b, x, SweepOrder::forward);
  Vector r;
  residual(a, s.b, x, r);
  double piece_residual = 0, piece_load = 0;
  for (const VertexId v : vertices) {
    piece_residual = std::max(piece_residual, r.segment<3>(3 * v).lpNorm<Eigen::Infinity>());
    piece_load = std::max(piece_load, s.b.segment<3>(3 * v).lpNorm<Eigen::Infinity>());
  }
  EXPECT_LT(piece_residual, 1e-10 * piece_load);
  // Only the piece's free dofs moved.
  std::vector<std::uint8_t> in_piece(static_cast<std::size_t>(model.volume.vertex_count()), 0);
  for (const VertexId v : vertices) in_piece[static_cast<std::size_t>(v)] = 1;
  for (Eigen::Index d = 0; d < x.size(); ++d) {
    if (!in_piece[static_cast<std::size_t>(d / 3)] || fixed[static_cast<std::size_t>(d)]) {
      EXPECT_EQ(x[d], before[d]) << "dof " << d;
    }
  }
  // The same in single precision reaches the float residual's level.
  Eigen::VectorXf xf = before.cast<float>();
  const BlockSparseMatrix<float> af = to_block_sparse<float>(s.a);
  const Eigen::VectorXf bf = s.b.cast<float>();
  pieces.correct(af, bf, xf, SweepOrder::backward);
  EXPECT_LT((xf.cast<double>() - x).lpNorm<Eigen::Infinity>(), 1e-4 * x.lpNorm<Eigen::Infinity>());
}

// Pieces of one colour are solved in parallel: none may read (a column of its rows) a dof that
// another of its colour writes (its own vertices). Columns two cells apart read each other
// through the plate cells under them; four apart they do not.
TEST(WeakPieces, NoPieceOfAColourReadsWhatAnotherOfItWrites) {
  std::vector<Eigen::Vector2i> columns;
  for (int x = 1; x < 15; x += 2) columns.push_back(Eigen::Vector2i(x, 2));
  for (int x = 1; x < 15; x += 4) columns.push_back(Eigen::Vector2i(x, 6));
  const TissueModel model = make_plate_with_columns({16, 8, 2}, 4, columns, 2.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const BlockSparseMatrix<double> a = to_block_sparse<double>(s.a);
  WeakPieceSolves pieces = find_weak_pieces(grid_level_of(model.volume), {});
  pieces.factor(a, identity_rows(a));
  ASSERT_EQ(pieces.piece_count(), static_cast<int>(columns.size()));
  ASSERT_GE(pieces.colour_count(), 2);
  int checked_pairs = 0;
  for (int c = 0; c < pieces.colour_count(); ++c) {
    const std::vector<int> members = pieces.colour_pieces(c);
    for (const int p : members)
      for (const int q : members) {
        if (p == q) continue;
        const std::vector<VertexId> writes = pieces.piece_vertices(q);
        for (const VertexId v : pieces.piece_vertices(p))
          for (auto k = a.row_start[static_cast<std::size_t>(v)]; k < a.row_start[static_cast<std::size_t>(v) + 1]; ++k) {
            EXPECT_FALSE(std::binary_search(writes.begin(), writes.end(), a.column[static_cast<std::size_t>(k)]))
                << "pieces " << p << " and " << q << " of colour " << c;
          }
        ++checked_pairs;
      }
  }
  EXPECT_GT(checked_pairs, 0);
}

TEST(WeakPieces, RefuseAMatrixOfAnotherLevel) {
  const TissueModel model = make_plate_with_columns({4, 4, 2}, 3, {Eigen::Vector2i(1, 1)}, 2.0);
  WeakPieceSolves pieces = find_weak_pieces(grid_level_of(model.volume), {});
  const SparseMatrix a = assemble_stiffness(test::make_box({2, 2, 2}, 2.0));
  try {
    pieces.factor(to_block_sparse<double>(a), std::vector<std::uint8_t>(static_cast<std::size_t>(a.rows()), 0));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "weak pieces: matrix of 81 rows and 81 fixed flags for a level of 87 vertices; expected 261 each");
  }
}

MultigridPreconditioner plate_multigrid(const TissueModel& model, const SparseMatrix& a, int max_links) {
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  options.precision = CyclePrecision::double_precision;
  options.weak_pieces.max_links = max_links;
  return build_multigrid(a, model.volume, options);
}

// The pieces' solves go before the coarse correction in one order and after it in the reverse
// order, so the V-cycle stays a symmetric operator (CG needs it).
TEST(WeakPieces, KeepTheVCycleSymmetric) {
  const TissueModel model = make_plate_with_columns({16, 8, 2}, 6, {Eigen::Vector2i(3, 3), Eigen::Vector2i(4, 3), Eigen::Vector2i(12, 5)}, 2.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const MultigridPreconditioner m = plate_multigrid(model, s.a, 2);
  ASSERT_GE(m.levels().size(), 2u);
  ASSERT_GE(m.levels()[0].weak_pieces.factored_count(), 2);
  std::srand(7);
  Vector u = Vector::Random(s.b.size()), v = Vector::Random(s.b.size());
  for (Eigen::Index d = 0; d < u.size(); ++d)
    if (m.levels()[0].fixed[static_cast<std::size_t>(d)]) u[d] = v[d] = 0;
  Vector mu, mv;
  m.apply(u, mu);
  m.apply(v, mv);
  EXPECT_NEAR(v.dot(mu), u.dot(mv), 1e-10 * std::abs(v.dot(mu)));
}

int plate_iterations(const TissueModel& model, int max_links, Vector& x) {
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const MultigridPreconditioner m = plate_multigrid(model, s.a, max_links);
  SolveSettings settings;
  settings.relative_tolerance = 1e-9;
  x = Vector::Zero(s.b.size());
  const SolveReport r = preconditioned_cg(s.a, s.b, x, m, settings);
  EXPECT_TRUE(r.converged);
  return r.iterations;
}

// Slender columns on a plate: their bending modes are what the smoother and the coarse space
// miss (103 iterations against 22 for the bare plate when this was written); with their pieces
// solved exactly the cycle needs a third of that (32), and the solution is the same.
TEST(WeakPieces, SlenderColumnsCostTheMultigridNoExtraIterations) {
  std::vector<Eigen::Vector2i> columns;
  for (int x = 1; x < 32; x += 5)
    for (int y = 1; y < 16; y += 5) columns.push_back(Eigen::Vector2i(x, y));
  const TissueModel with_columns = make_plate_with_columns({32, 16, 3}, 8, columns, 1.0);
  const TissueModel plate = test::make_box({32, 16, 3}, 1.0);
  Vector x_off, x_on, x_plate;
  const int off = plate_iterations(with_columns, 0, x_off);
  const int on = plate_iterations(with_columns, 2, x_on);
  const int bare = plate_iterations(plate, 2, x_plate);
  std::printf("plate 32x16x3 with %zu columns of 8 cells: %d iterations without the pieces' solves, %d with; bare plate %d\n",
              columns.size(), off, on, bare);
  EXPECT_LE(on, 3 * bare / 2);
  EXPECT_LT(on, off / 2);
  EXPECT_LT((x_on - x_off).norm(), 1e-7 * x_off.norm());
}

}  // namespace
}  // namespace cleave
