// The cut-aware multigrid: prolongation reproduces linear fields, coarse operators are Galerkin
// products that keep the rigid null space, pieces separated by a cut stay uncoupled on every level,
// and the iteration count of multigrid-preconditioned CG stays flat under cuts and refinement.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/galerkin_operator.hpp"
#include "cleave/solve/grid_level.hpp"
#include "cleave/solve/multigrid_cg_solver.hpp"
#include "cleave/solve/multigrid_preconditioner.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

/// Position of every vertex of a level (in cells of that level, i.e. grid corner coordinates).
std::vector<Vec3> level_vertex_positions(const GridLevel& level) {
  std::vector<Vec3> p(static_cast<std::size_t>(level.vertex_count), Vec3::Zero());
  for (CellId c = 0; c < level.cell_count(); ++c)
    for (int k = 0; k < kCornerCount; ++k)
      p[static_cast<std::size_t>(level.cell_vertices[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)])] =
          (level.cell_voxel[static_cast<std::size_t>(c)] + corner_offset(k)).cast<double>();
  return p;
}

/// a with its diagonal raised by `fraction` of itself (new values on the same pattern), compressed.
SparseMatrix with_diagonal_raised(const SparseMatrix& a, double fraction) {
  SparseMatrix out = a;
  for (Eigen::Index i = 0; i < out.rows(); ++i) out.coeffRef(i, i) += fraction * a.coeff(i, i);
  out.makeCompressed();
  return out;
}

TEST(Prolongation, ReproducesLinearFieldsAndPartitionsUnity) {
  TissueModel model = test::make_box({7, 6, 3}, 1.0);  // odd sizes: partial blocks at the ends
  test::cut_across_middle(model, 4);
  GridLevel fine = grid_level_of(model.volume);
  for (int step = 0; step < 3; ++step) {
    const Coarsening next = coarsen_grid_level(fine);
    const auto fine_positions = level_vertex_positions(fine);
    const auto coarse_positions = level_vertex_positions(next.coarse);
    const Prolongation& p = next.prolongation;
    ASSERT_EQ(p.fine_count(), fine.vertex_count);
    for (VertexId v = 0; v < fine.vertex_count; ++v) {
      double weights = 0;
      Vec3 interpolated = Vec3::Zero();
      for (int e = p.fine_start[static_cast<std::size_t>(v)]; e < p.fine_start[static_cast<std::size_t>(v) + 1]; ++e) {
        const auto& entry = p.by_fine[static_cast<std::size_t>(e)];
        weights += entry.weight;
        interpolated += entry.weight * 2.0 * coarse_positions[static_cast<std::size_t>(entry.vertex)];
      }
      EXPECT_NEAR(weights, 1.0, 1e-15) << "level " << step << " vertex " << v;
      EXPECT_LT((interpolated - fine_positions[static_cast<std::size_t>(v)]).norm(), 1e-12) << "level " << step << " vertex " << v;
    }
    EXPECT_LT(next.coarse.cell_count(), fine.cell_count());
    fine = next.coarse;
  }
}

TEST(GalerkinOperator, EqualsTheExplicitTripleProductAndKeepsRigidTranslations) {
  const TissueModel model = test::make_box({6, 5, 4}, 2.0);
  const SparseMatrix k = assemble_stiffness(model);
  const Coarsening next = coarsen_grid_level(grid_level_of(model.volume));
  const Prolongation& p = next.prolongation;
  Eigen::SparseMatrix<double> pd(3 * p.fine_count(), 3 * p.coarse_count());
  std::vector<Eigen::Triplet<double>> entries;
  for (VertexId v = 0; v < p.fine_count(); ++v)
    for (int e = p.fine_start[static_cast<std::size_t>(v)]; e < p.fine_start[static_cast<std::size_t>(v) + 1]; ++e)
      for (int axis = 0; axis < 3; ++axis)
        entries.emplace_back(3 * v + axis, 3 * p.by_fine[static_cast<std::size_t>(e)].vertex + axis,
                             p.by_fine[static_cast<std::size_t>(e)].weight);
  pd.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SparseMatrix<double> kc(k);
  const Eigen::MatrixXd expected = Eigen::MatrixXd(Eigen::SparseMatrix<double>(pd.transpose() * kc * pd));
  const std::vector<std::uint8_t> none(static_cast<std::size_t>(k.rows()), 0);
  const Eigen::MatrixXd galerkin = Eigen::MatrixXd(galerkin_operator(k, none, p));
  EXPECT_LT((galerkin - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  for (int axis = 0; axis < 3; ++axis) {
    const Vector translation = Vector::NullaryExpr(galerkin.rows(), [&](Eigen::Index i) { return i % 3 == axis ? 1.0 : 0.0; });
    const Vector force = galerkin * translation;
    EXPECT_LT(force.cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff()) << "axis " << axis;
  }
}

// The Galerkin product from the block CSR copy (what the multigrid solver passes, to skip a second
// conversion) is the one from the scalar matrix, bit for bit, with fixed dofs; sizes that do not
// fit the prolongation are refused by name.
TEST(GalerkinOperator, FromBlocksEqualsFromTheScalarMatrix) {
  const TissueModel model = test::make_box({6, 5, 4}, 2.0);
  const SparseMatrix k = assemble_stiffness(model);
  const Prolongation p = coarsen_grid_level(grid_level_of(model.volume)).prolongation;
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(k.rows()), 0);
  for (std::size_t i = 0; i < fixed.size(); i += 7) fixed[i] = 1;
  const SparseMatrix from_scalar = galerkin_operator(k, fixed, p);
  const SparseMatrix from_blocks = galerkin_operator(to_block_sparse<double>(k), fixed, p);
  ASSERT_EQ(from_blocks.nonZeros(), from_scalar.nonZeros());
  EXPECT_EQ(Eigen::MatrixXd(from_blocks), Eigen::MatrixXd(from_scalar));
  const std::vector<std::uint8_t> short_flags(fixed.size() - 3, 0);
  try {
    (void)galerkin_operator(to_block_sparse<double>(k), short_flags, p);
    ADD_FAILURE() << "fixed flags of the wrong size were accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              fmt::format("galerkin operator: {} block rows and {} fixed flags for a prolongation from {} fine vertices; expected {} "
                          "and {}",
                          model.volume.vertex_count(), short_flags.size(), model.volume.vertex_count(), model.volume.vertex_count(),
                          fixed.size()));
  }
}

// The fixed dofs read off the block copy are those read off the scalar matrix: rows eliminated
// to identity, and no others (a row whose only off-diagonal entries are zero counts; one with a
// zero diagonal does not).
TEST(GalerkinOperator, IdentityRowsOfTheBlocksAreThoseOfTheScalarMatrix) {
  const TissueModel model = test::make_box({6, 5, 4}, 2.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const std::vector<std::uint8_t> from_scalar = identity_rows(s.a);
  const auto held = static_cast<std::size_t>(std::count(from_scalar.begin(), from_scalar.end(), std::uint8_t{1}));
  EXPECT_EQ(held, 3u * 5u * 6u);  // the 6 x 5 vertices of the plane x = 0, three dofs each
  EXPECT_EQ(identity_rows(to_block_sparse<double>(s.a)), from_scalar);
  SparseMatrix zero_diagonal = s.a;
  for (Eigen::Index row = 0; row < zero_diagonal.rows(); ++row)
    if (from_scalar[static_cast<std::size_t>(row)] != 0) {
      zero_diagonal.coeffRef(row, row) = 0.0;
      break;
    }
  const std::vector<std::uint8_t> fewer = identity_rows(to_block_sparse<double>(zero_diagonal));
  EXPECT_EQ(static_cast<std::size_t>(std::count(fewer.begin(), fewer.end(), std::uint8_t{1})), held - 1);
  EXPECT_EQ(fewer, identity_rows(zero_diagonal));
}

// The hierarchy keeps no reference to the matrix it was built from: one built from a temporary
// (scalar or block CSR) applies the same cycle as one built from a matrix that lives on (under
// ASan a kept reference reads freed memory). Level 0 has no scalar operator to hand out.
TEST(Multigrid, TheHierarchyOwnsItsOperators) {
  const TissueModel model = test::make_box({16, 8, 4}, 2.5);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  const MultigridPreconditioner kept = build_multigrid(s.a, model.volume, options);
  const MultigridPreconditioner from_temporary = build_multigrid(SparseMatrix(s.a), model.volume, options);
  const MultigridPreconditioner from_blocks = build_multigrid(to_block_sparse<double>(s.a), model.volume, options);
  ASSERT_GE(kept.levels().size(), 3u);
  Vector z_kept, z_temporary, z_blocks;
  kept.apply(s.b, z_kept);
  from_temporary.apply(s.b, z_temporary);
  from_blocks.apply(s.b, z_blocks);
  EXPECT_GT(z_kept.norm(), 0.0);
  EXPECT_EQ(z_temporary, z_kept);
  EXPECT_EQ(z_blocks, z_kept);
  EXPECT_EQ(kept.coarse_operator(1).rows(), 3 * static_cast<Eigen::Index>(kept.levels()[1].smoother.inverse_diagonal.size()));
  try {
    (void)kept.coarse_operator(0);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("multigrid: level 0 has no coarse operator; expected 1 to {}", kept.levels().size() - 1));
  }
}

/// Component of each vertex of every level, propagated through the prolongations; checks on the
/// way that no coarse vertex takes values from fine vertices of two different pieces.
std::vector<std::vector<int>> level_components(const MultigridPreconditioner& m, const LinkedVolume& volume) {
  std::vector<int> fine(static_cast<std::size_t>(volume.vertex_count()), -1);
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (const VertexId v : volume.cell_vertices(c)) fine[static_cast<std::size_t>(v)] = volume.cell_components()[static_cast<std::size_t>(c)];
  std::vector<std::vector<int>> out{fine};
  for (std::size_t l = 0; l + 1 < m.levels().size(); ++l) {
    const Prolongation& p = m.levels()[l].from_coarser;
    std::vector<int> coarse(static_cast<std::size_t>(p.coarse_count()), -1);
    for (VertexId v = 0; v < p.coarse_count(); ++v)
      for (int e = p.coarse_start[static_cast<std::size_t>(v)]; e < p.coarse_start[static_cast<std::size_t>(v) + 1]; ++e) {
        const int piece = out.back()[static_cast<std::size_t>(p.by_coarse[static_cast<std::size_t>(e)].vertex)];
        int& mine = coarse[static_cast<std::size_t>(v)];
        EXPECT_TRUE(mine == -1 || mine == piece) << "level " << l + 1 << " vertex " << v << " mixes pieces";
        mine = piece;
      }
    out.push_back(std::move(coarse));
  }
  return out;
}

TEST(Multigrid, CoarseLevelsDoNotCoupleThePiecesOfAFullCut) {
  TissueModel model = test::make_box({32, 16, 4}, 2.5);
  test::cut_across_middle(model, 16);  // through the whole width: two pieces
  ASSERT_EQ(model.volume.component_count(), 2);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::both_ends);
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  options.coarsest_factor_share = 0;  // every level down to 100 dofs
  const MultigridPreconditioner m = build_multigrid(s.a, model.volume, options);
  ASSERT_GE(m.levels().size(), 4u);
  const auto components = level_components(m, model.volume);
  for (std::size_t l = 1; l < m.levels().size(); ++l) {
    const SparseMatrix& a = m.coarse_operator(l);
    std::map<int, int> vertices_per_piece;
    for (int piece : components[l]) ++vertices_per_piece[piece];
    EXPECT_GE(vertices_per_piece[0], 1) << "level " << l;
    EXPECT_GE(vertices_per_piece[1], 1) << "level " << l;
    int couplings = 0;
    for (Eigen::Index row = 0; row < a.outerSize(); ++row)
      for (SparseMatrix::InnerIterator it(a, row); it; ++it) {
        if (it.value() == 0) continue;
        const int pr = components[l][static_cast<std::size_t>(it.row() / 3)];
        const int pc = components[l][static_cast<std::size_t>(it.col() / 3)];
        if (pr != -1 && pc != -1 && pr != pc) ++couplings;
      }
    EXPECT_EQ(couplings, 0) << "level " << l;
  }
  // And the solve is right: compare with the direct solver.
  SolveSettings settings;
  settings.relative_tolerance = 1e-10;
  auto mg = make_multigrid_cg_solver(settings, options);
  auto direct = make_linear_solver(SolverKind::cholmod, settings);
  mg->setup(s.a, model.volume);
  direct->setup(s.a, model.volume);
  Vector x_mg = Vector::Zero(s.b.size()), x_direct = Vector::Zero(s.b.size());
  const SolveReport r = mg->solve(s.b, x_mg);
  direct->solve(s.b, x_direct);
  std::printf("fully cut plate: multigrid %d iterations over %zu levels\n", r.iterations, m.levels().size());
  EXPECT_TRUE(r.converged);
  EXPECT_LT((x_mg - x_direct).norm() / x_direct.norm(), 1e-6);
}

std::vector<std::ptrdiff_t> free_dofs_per_level(const MultigridPreconditioner& m) {
  std::vector<std::ptrdiff_t> free;
  for (const MultigridLevel& level : m.levels())
    free.push_back(std::count(level.fixed.begin(), level.fixed.end(), std::uint8_t{0}));
  return free;
}

// The coarsest level is chosen by free dofs: a held piece (the removed plug of a round incision)
// keeps its coarse replicas on every level but adds nothing to solve, so it must not deepen the
// hierarchy (with 108 plugs at 44k cells it had added a fifth level: 30 iterations instead of 29).
TEST(Multigrid, AHeldPieceDoesNotDeepenTheHierarchy) {
  MultigridOptions options;
  options.coarsest_max_dofs = 230;
  const TissueModel half = test::make_box({8, 8, 4}, 2.5);
  const test::LinearSystem alone = test::clamped_system(half, test::Clamp::left_end);
  TissueModel both = test::make_box({16, 8, 4}, 2.5);
  test::cut_across_middle(both, 8);  // two pieces
  SparseMatrix k = assemble_stiffness(both);
  Vector b = Vector::Zero(k.rows());
  std::vector<VertexId> held;
  for (VertexId v = 0; v < both.volume.vertex_count(); ++v) {
    const Vec3 p = both.volume.vertex_position_mm(v);
    const bool right_piece = std::any_of(both.volume.vertex_cells()[static_cast<std::size_t>(v)].begin(),
                                         both.volume.vertex_cells()[static_cast<std::size_t>(v)].end(),
                                         [&](CellId c) { return both.volume.cell_voxel(c).x() >= 8; });
    if (p.x() < 1e-9 || right_piece) held.push_back(v);
  }
  eliminate_fixed_dofs(k, b, fix_vertices(both.volume.vertex_count(), held));
  k.makeCompressed();
  const MultigridPreconditioner m_alone = build_multigrid(alone.a, half.volume, options);
  const MultigridPreconditioner m_both = build_multigrid(k, both.volume, options);
  EXPECT_EQ(m_alone.levels().size(), 2u);
  EXPECT_EQ(free_dofs_per_level(m_both), free_dofs_per_level(m_alone));
  EXPECT_GT(m_both.levels().back().fixed.size(), m_alone.levels().back().fixed.size());  // the held piece's replicas
}

int multigrid_iterations(const TissueModel& model, test::Clamp clamp, const MultigridOptions& options) {
  const test::LinearSystem s = test::clamped_system(model, clamp);
  SolveSettings settings;
  settings.relative_tolerance = 1e-8;
  auto solver = make_multigrid_cg_solver(settings, options);
  solver->setup(s.a, model.volume);
  Vector x = Vector::Zero(s.b.size());
  const SolveReport r = solver->solve(s.b, x);
  EXPECT_TRUE(r.converged);
  return r.iterations;
}

TEST(Multigrid, PartialCutNeedsAboutAsManyIterationsAsUncut) {
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  TissueModel model = test::make_box({32, 16, 4}, 2.5);
  const int uncut = multigrid_iterations(model, test::Clamp::left_end, options);
  test::cut_across_middle(model, 11);
  const int cut = multigrid_iterations(model, test::Clamp::left_end, options);
  std::printf("plate 32x16x4: %d iterations uncut, %d with a partial cut\n", uncut, cut);
  EXPECT_LE(cut, uncut * 3 / 2 + 1);
}

TEST(Multigrid, IterationsStayFlatUnderRefinement) {
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  std::vector<int> iterations;
  for (const int n : {3, 6, 12}) {  // a 40 x 20 x 10 mm block with 3, 6, 12 cells through 10 mm
    const TissueModel model = test::make_box({4 * n, 2 * n, n}, 10.0 / n);
    iterations.push_back(multigrid_iterations(model, test::Clamp::left_end, options));
    std::printf("block 40x20x10 mm, %d cells: %d iterations\n", 8 * n * n * n, iterations.back());
  }
  EXPECT_LT(iterations.back(), 1.5 * iterations.front());
}

// The coarse levels smooth with their own Chebyshev degree: the fine level keeps smoother.degree,
// and a better coarse correction (degree 3 against 1) saves iterations on the refined block.
TEST(Multigrid, CoarseLevelsSmoothWithTheirOwnDegree) {
  const TissueModel model = test::make_box({48, 24, 12}, 10.0 / 12);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  options.coarse_degree = 4;
  const MultigridPreconditioner m = build_multigrid(s.a, model.volume, options);
  ASSERT_GE(m.levels().size(), 3u);
  EXPECT_EQ(m.levels()[0].smoother.options.degree, options.smoother.degree);
  for (std::size_t l = 1; l + 1 < m.levels().size(); ++l) EXPECT_EQ(m.levels()[l].smoother.options.degree, 4);
  options.coarse_degree = 1;
  const int plain = multigrid_iterations(model, test::Clamp::left_end, options);
  options.coarse_degree = 3;
  const int deeper = multigrid_iterations(model, test::Clamp::left_end, options);
  std::printf("block 48x24x12: %d iterations with coarse degree 1, %d with 3\n", plain, deeper);
  EXPECT_LT(deeper, plain);
  options.coarse_degree = 0;
  try {
    (void)build_multigrid(s.a, model.volume, options);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "multigrid: coarse smoother degree is 0; expected 1 or more");
  }
}

// The fine level's Chebyshev interval and degree can differ from the coarse levels' (the
// real-time step's fine level: degree 1 over [lambda_max / 4, lambda_max]); bad ones are refused.
TEST(Multigrid, TheFineLevelSmoothsOverItsOwnInterval) {
  const TissueModel model = test::make_box({48, 24, 12}, 10.0 / 12);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  options.smoother.degree = 1;
  options.smoother.smoothing_range = 4.0;
  const MultigridPreconditioner m = build_multigrid(s.a, model.volume, options);
  ASSERT_GE(m.levels().size(), 3u);
  EXPECT_EQ(m.levels()[0].smoother.options.degree, 1);
  EXPECT_EQ(m.levels()[0].smoother.options.smoothing_range, 4.0);
  for (std::size_t l = 1; l + 1 < m.levels().size(); ++l) {
    EXPECT_EQ(m.levels()[l].smoother.options.degree, options.coarse_degree);
    EXPECT_EQ(m.levels()[l].smoother.options.smoothing_range, options.coarse_smoothing_range);
  }
  // Still a preconditioner that converges: CG with it solves the clamped block.
  EXPECT_LT(multigrid_iterations(model, test::Clamp::left_end, options), 60);
  const auto refusal = [&](const MultigridOptions& bad) {
    try {
      (void)build_multigrid(s.a, model.volume, bad);
      return std::string("no error");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
  };
  MultigridOptions bad = options;
  bad.smoother.degree = 0;
  EXPECT_EQ(refusal(bad), "multigrid: fine smoother degree is 0; expected 1 or more");
  bad = options;
  bad.smoother.smoothing_range = 1.0;
  EXPECT_EQ(refusal(bad), "multigrid: smoothing range is 1; expected a finite ratio above 1 (lambda_max over the lower end of "
                          "the damped interval)");
  bad = options;
  bad.coarse_smoothing_range = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(refusal(bad), "multigrid: smoothing range is nan; expected a finite ratio above 1 (lambda_max over the lower end of "
                          "the damped interval)");
}

// A solve with kept (stale) coarse levels that needs far more iterations than the first solve
// after the build rebuilds the levels from the current values mid-solve and goes on from where it
// got (the studio's corotated free plugs at 45k cells: 1,426 iterations before, 55 to 77 after).
// A diagonal shift (a changed mass term) is the change the stale levels fit worst.
TEST(Multigrid, AStaleSolveFarAboveTheFirstRebuildsItsLevelsAndGoesOn) {
  TissueModel model = test::make_box({32, 16, 4}, 1.0);
  test::cut_across_middle(model, 10);
  const test::LinearSystem system = test::clamped_system(model, test::Clamp::both_ends);
  const SparseMatrix shifted = with_diagonal_raised(system.a, 0.2);
  SolveSettings settings;
  settings.relative_tolerance = 1e-10;
  const auto stale_solve = [&](double rebuild_factor, int& first_iterations) {
    MultigridOptions options;
    options.coarsest_max_dofs = 100;
    options.stale_solve_rebuild_factor = rebuild_factor;
    auto solver = make_multigrid_cg_solver(settings, options);
    solver->setup(system.a, model.volume);
    Vector x = Vector::Zero(system.b.size());
    first_iterations = solver->solve(system.b, x).iterations;
    solver->update_values(shifted, model.volume);
    x.setZero();
    const SolveReport r = solver->solve(system.b, x);
    EXPECT_TRUE(r.converged);
    EXPECT_LT((shifted * x - system.b).norm(), 1e-9 * system.b.norm());
    return r.iterations;
  };
  int first = 0;
  const int kept = stale_solve(0.0, first);
  const int rebuilt = stale_solve(1.0, first);  // rebuild once above the first solve + 10 (default factor 3)
  std::printf("stale levels after a 20 %% diagonal shift: %d iterations kept, %d with the rebuild (first solve %d)\n", kept,
              rebuilt, first);
  ASSERT_GT(kept, first + 10) << "the scenario must make the stale levels slow";
  EXPECT_LT(rebuilt, kept);
}

// The dynamics hands each step's matrix to the multigrid as block CSR (update_block_values). That
// must be the same update as the scalar one: the same iterations and the same solution; and a
// matrix of another pattern is refused (the caller then gives the scalar matrix, as it does while
// a rebuild is due).
TEST(Multigrid, NewValuesAsBlocksAreTheSameUpdateAsTheScalarMatrix) {
  TissueModel model = test::make_box({16, 8, 4}, 1.0);
  test::cut_across_middle(model, 6);
  const test::LinearSystem system = test::clamped_system(model, test::Clamp::both_ends);
  const SparseMatrix shifted = with_diagonal_raised(system.a, 0.05);
  SolveSettings settings;
  settings.relative_tolerance = 1e-10;
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  const auto solve_after = [&](bool as_blocks, SolveReport& report) {
    auto solver = make_multigrid_cg_solver(settings, options);
    solver->setup(system.a, model.volume);
    Vector x = Vector::Zero(system.b.size());
    solver->solve(system.b, x);
    if (as_blocks) {
      BlockSparseMatrix<double> blocks = to_block_sparse<double>(shifted);
      const BlockSparseMatrix<double> given = blocks;
      EXPECT_TRUE(solver->update_block_values(blocks, model.volume));
      // The values were exchanged, not copied: `blocks` keeps its pattern and now holds the old matrix's.
      EXPECT_EQ(blocks.row_start, given.row_start);
      EXPECT_EQ(blocks.column, given.column);
      EXPECT_EQ(blocks.values, to_block_sparse<double>(system.a).values);
    } else {
      solver->update_values(shifted, model.volume);
    }
    x.setZero();
    report = solver->solve(system.b, x);
    return x;
  };
  SolveReport by_blocks, by_scalar;
  const Vector x_blocks = solve_after(true, by_blocks);
  const Vector x_scalar = solve_after(false, by_scalar);
  EXPECT_TRUE(by_blocks.converged);
  EXPECT_EQ(by_blocks.iterations, by_scalar.iterations);
  EXPECT_LE((x_blocks - x_scalar).norm(), 1e-12 * x_scalar.norm());
  EXPECT_LT((shifted * x_blocks - system.b).norm(), 1e-9 * system.b.norm());

  auto solver = make_multigrid_cg_solver(settings, options);
  solver->setup(system.a, model.volume);
  BlockSparseMatrix<double> other = to_block_sparse<double>(shifted);
  other.column.back() = other.column.front();  // another pattern
  EXPECT_FALSE(solver->update_block_values(other, model.volume));
}


/// For each vertex a cut created (ids from `before` on): the vertex it was copied from.
std::vector<VertexId> origins_of_new_vertices(const CutReport& report, VertexId before, VertexId after) {
  std::vector<VertexId> origin(static_cast<std::size_t>(after - before), kNone);
  for (const VertexSplit& split : report.splits)
    for (const VertexId v : split.created) origin[static_cast<std::size_t>(v - before)] = split.original;
  return origin;
}

/// Cuts the 32 x 16 x 4 box's slit across x = 15 for y < 10 (a partial cut: vertices divided,
/// one piece) and returns the origins of the vertices it created.
std::vector<VertexId> cut_partial_slit(TissueModel& model) {
  const VertexId before = model.volume.vertex_count();
  std::vector<CellFace> faces;
  for (CellId c = 0; c < model.volume.cell_count(); ++c) {
    const Vec3i& v = model.volume.cell_voxel(c);
    if (v.x() == 15 && v.y() < 10) faces.push_back({c, 1});
  }
  const CutReport report = model.volume.cut_links(faces);
  const VertexId after = model.volume.vertex_count();
  EXPECT_GT(after, before);
  return origins_of_new_vertices(report, before, after);
}

// After a cut divides vertices, the kept coarse levels with each copy's prolongation row taken
// from its origin are exactly the Galerkin operators of the new matrix (the elements do not
// change; only which vertices they share), so the multigrid keeps them: the solve converges to
// the new matrix's solution. Their coarse functions do not see the cut (they are continuous across
// it), so it takes more iterations than a fresh setup (here 43 against 18; 50 while the fine
// smoother's bound was re-estimated cold after a cut, up to session 24), bounded by 3x: the
// solver's iteration rule rebuilds the levels when a solve grows past 1.3x its first.
TEST(Multigrid, AfterACutTheKeptLevelsAreTheGalerkinOperatorsOfTheNewMatrix) {
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  TissueModel model = test::make_box({32, 16, 4}, 1.0);
  const test::LinearSystem uncut = test::clamped_system(model, test::Clamp::both_ends);
  SolveSettings settings;
  settings.relative_tolerance = 1e-10;
  auto solver = make_multigrid_cg_solver(settings, options);
  solver->setup(uncut.a, model.volume);
  auto reference = build_multigrid(uncut.a, model.volume, options);  // the levels the solver keeps
  Vector x = Vector::Zero(uncut.b.size());
  ASSERT_TRUE(solver->solve(uncut.b, x).converged);

  const VertexId before = model.volume.vertex_count();
  const std::vector<VertexId> origins = cut_partial_slit(model);
  const VertexId after = model.volume.vertex_count();
  ASSERT_GT(after, before);
  const test::LinearSystem cut = test::clamped_system(model, test::Clamp::both_ends);

  reference.replace_fine_level(to_block_sparse<double>(cut.a), origins, options.smoother);
  const MultigridLevel& fine = reference.levels()[0];
  EXPECT_EQ(fine.from_coarser.fine_count(), after);
  const SparseMatrix galerkin = galerkin_operator(cut.a, fine.fixed, fine.from_coarser);
  const SparseMatrix& kept = reference.levels()[1].matrix;
  ASSERT_EQ(galerkin.rows(), kept.rows());
  EXPECT_LT((galerkin - kept).norm(), 1e-12 * kept.norm());

  solver->update_topology(cut.a, model.volume, origins);
  Vector y = Vector::Zero(cut.b.size());
  const SolveReport kept_solve = solver->solve(cut.b, y);
  EXPECT_TRUE(kept_solve.converged);
  EXPECT_LT((cut.a * y - cut.b).norm(), 1e-9 * cut.b.norm());
  auto fresh = make_multigrid_cg_solver(settings, options);
  fresh->setup(cut.a, model.volume);
  Vector z = Vector::Zero(cut.b.size());
  const SolveReport fresh_solve = fresh->solve(cut.b, z);
  std::printf("after a partial cut (%d vertices divided): %d iterations with the kept levels, %d after a fresh setup\n",
              after - before, kept_solve.iterations, fresh_solve.iterations);
  EXPECT_LE(kept_solve.iterations, 3 * fresh_solve.iterations);
  EXPECT_LT((y - z).norm(), 1e-7 * z.norm());
}

// After a cut the fine smoother's bound lambda_max(D^-1 A) is re-estimated from the last power
// iteration's vector (a third of the products of a cold estimate): it must still bound the true
// largest eigenvalue, stay close to it, and a warm start that does not fit falls back to cold.
TEST(Multigrid, AfterACutTheSmootherBoundStartsWarmAndStillBoundsTheSpectrum) {
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  TissueModel model = test::make_box({32, 16, 4}, 1.0);
  const test::LinearSystem uncut = test::clamped_system(model, test::Clamp::both_ends);
  MultigridPreconditioner m = build_multigrid(uncut.a, model.volume, options);
  const double before_cut = m.levels()[0].smoother.lambda_max;
  ASSERT_EQ(m.levels()[0].smoother.lambda_vector.size(), uncut.a.rows());

  const std::vector<VertexId> origins = cut_partial_slit(model);
  ASSERT_FALSE(origins.empty());
  const test::LinearSystem cut = test::clamped_system(model, test::Clamp::both_ends);
  const BlockSparseMatrix<double> cut_blocks = to_block_sparse<double>(cut.a);
  m.replace_fine_level(cut_blocks, origins, options.smoother);
  const ChebyshevSmoother& warm = m.levels()[0].smoother;
  EXPECT_EQ(warm.lambda_vector.size(), cut.a.rows());
  EXPECT_NEAR(warm.lambda_vector.norm(), 1.0, 1e-12);

  // The spectrum's top by a long power iteration, without the safety factor.
  ChebyshevOptions exact = options.smoother;
  exact.power_iterations = 400;
  exact.lambda_safety_factor = 1.0;
  const double largest = make_chebyshev_smoother(cut_blocks, exact).lambda_max;
  const double cold = make_chebyshev_smoother(cut_blocks, options.smoother).lambda_max;
  std::printf("lambda_max(D^-1 A) after the cut %.4f (400 iterations); its bound %.4f before the cut, %.4f warm (%d iterations), "
              "%.4f cold (%d)\n",
              largest, before_cut, warm.lambda_max, options.smoother.warm_power_iterations, cold, options.smoother.power_iterations);
  EXPECT_GE(warm.lambda_max, largest);
  EXPECT_GE(warm.lambda_max, before_cut);  // never lowered by the short iteration
  EXPECT_LE(warm.lambda_max, 1.2 * largest);
  EXPECT_NEAR(warm.lambda_max, cold, 0.05 * cold);

  // A vector of another size is no warm start: the estimate is the cold one, bit for bit.
  const std::vector<VertexId> one_too_many(origins.size() + 1, 0);
  const ChebyshevSmoother unfit = make_chebyshev_smoother(cut_blocks, options.smoother, ChebyshevWarmStart{&warm, &one_too_many});
  EXPECT_EQ(unfit.lambda_max, cold);
}

TEST(Multigrid, ReplacingTheFineLevelRefusesOriginsOutsideTheOldLevel) {
  MultigridOptions options;
  options.coarsest_max_dofs = 100;
  const TissueModel model = test::make_box({16, 8, 2}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  auto m = build_multigrid(s.a, model.volume, options);
  const VertexId n = model.volume.vertex_count();
  // One copy claimed, of a vertex that does not exist; the matrix is sized for it.
  SparseMatrix grown(s.a.rows() + 3, s.a.cols() + 3);
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < s.a.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(s.a, r); it; ++it) entries.emplace_back(r, static_cast<int>(it.col()), it.value());
  for (int i = 0; i < 3; ++i) entries.emplace_back(3 * n + i, 3 * n + i, 1.0);
  grown.setFromTriplets(entries.begin(), entries.end());
  grown.makeCompressed();
  try {
    m.replace_fine_level(to_block_sparse<double>(grown), {n + 5}, options.smoother);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("multigrid: a divided vertex's origin is {}; expected a vertex of the old fine level (0 to {})", n + 5, n - 1));
  }
  try {
    m.replace_fine_level(to_block_sparse<double>(s.a), {0}, options.smoother);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("multigrid: the new fine matrix has {} rows; expected {} ({} vertices and 1 copies, 3 dofs each)",
                                                 s.a.rows(), 3 * (n + 1), n));
  }
}

// A cantilevered plate 4 cells thick: coarse cells 8 or 16 cells wide stiffen its bending. Its
// level of 2,646 dofs (cells 4 wide) factors cheaply, and the default hierarchy stops there: 17
// iterations, against 21 one level deeper (where the dof count alone would stop).
TEST(Multigrid, AThinPlateKeepsACoarsestLevelThatBends) {
  const TissueModel model = test::make_box({80, 80, 4}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  EXPECT_EQ(build_multigrid(s.a, model.volume).levels().size(), 3u);
  const int iterations = multigrid_iterations(model, test::Clamp::left_end, MultigridOptions{});
  MultigridOptions by_dofs;
  by_dofs.coarsest_factor_share = 0;
  const int deeper = multigrid_iterations(model, test::Clamp::left_end, by_dofs);
  std::printf("plate 80x80x4 cantilever: %d iterations, %d by the dof count alone\n", iterations, deeper);
  EXPECT_LE(iterations, 18);
  EXPECT_GT(deeper, iterations);
}

TEST(Multigrid, RefusesACoarsestFactorBudgetOutsideItsRange) {
  const TissueModel model = test::make_box({4, 4, 2}, 1.0);
  const test::LinearSystem s = test::clamped_system(model, test::Clamp::left_end);
  const auto message_of = [&](const MultigridOptions& options) -> std::string {
    try {
      (void)build_multigrid(s.a, model.volume, options);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  MultigridOptions share;
  share.coarsest_factor_share = -0.1;
  EXPECT_EQ(message_of(share), "multigrid: coarsest factor share is -0.1; expected a share from 0 to 1 of the fine matrix's entries");
  share.coarsest_factor_share = std::nan("");
  EXPECT_EQ(message_of(share), "multigrid: coarsest factor share is nan; expected a share from 0 to 1 of the fine matrix's entries");
  MultigridOptions flops;
  flops.coarsest_factor_flops_per_fine_entry = -1;
  EXPECT_EQ(message_of(flops), "multigrid: coarsest factor flops per fine entry is -1; expected a finite number of 0 or more");
  EXPECT_EQ(message_of(MultigridOptions{}), "no error");
}

}  // namespace
}  // namespace cleave
