// The dynamic step's system applied cell by cell (CorotatedSystemOperator) must be the matrix the
// step assembles: c_k R K^e R^T + c_s K_sigma + c_m M with fixed dofs eliminated, gathered here
// independently into scalar CSR on a cut two-material body under tension with held vertices and
// single held axes. And Dynamics must step the same with it as with the assembled matrix.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotated_system_operator.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/stress_stiffness.hpp"
#include "cleave/fem/vertex_block_matrix.hpp"
#include "cleave/solve/block_jacobi.hpp"
#include "cleave/solve/multigrid_cg_solver.hpp"
#include "cleave/solve/multigrid_preconditioner.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

constexpr double kStiff = 0.8, kStress = 0.8, kMass = 2.5e5;

/// A two-material box with a cut that frees a corner block: divided vertices, two pieces.
TissueModel cut_two_material_box() {
  TissueModel model = test::make_box_model({6, 5, 3}, 1.5, 60.0, 0.42, [](const Vec3i& v) { return Label(v.z() >= 1 ? 2 : 1); },
                                           {{Label{2}, Material{"stiff", 180.0, 0.3, 1100.0}}});
  model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
    const Vec3i v = model.volume.cell_voxel(c);
    return v.x() < 2 && v.y() < 2;
  }));
  return model;
}

/// Whole vertices held, and single axes of others.
std::vector<std::uint8_t> held_dofs(const LinkedVolume& volume) {
  std::vector<std::uint8_t> fixed(3 * static_cast<std::size_t>(volume.vertex_count()), 0);
  for (VertexId v = 0; v < volume.vertex_count(); v += 9)
    for (int i = 0; i < 3; ++i) fixed[static_cast<std::size_t>(3 * v + i)] = 1;
  for (VertexId v = 4; v < volume.vertex_count(); v += 13) fixed[static_cast<std::size_t>(3 * v + 1)] = 1;
  return fixed;
}

struct Fixture {
  TissueModel model = cut_two_material_box();
  ElementTable table = make_element_table(model);
  std::vector<Mat3> rotations;
  std::vector<Vec6> tension;
  Vector mass;
  std::vector<std::uint8_t> fixed;

  Fixture() {
    std::vector<Vec6> residual(static_cast<std::size_t>(model.volume.cell_count()));
    for (std::size_t c = 0; c < residual.size(); ++c) {
      residual[c] << 20.0 + static_cast<double>(c % 5), 8.0, -3.0 * static_cast<double>(c % 2), 2.0, 0.5, -1.0;
    }
    cell_rotations_and_tension(model.volume, table, residual, test::turned_displacement(model.volume), rotations, tension);
    mass = lumped_mass(model, table);
    fixed = held_dofs(model.volume);
  }

  /// The system gathered into scalar CSR and eliminated as the assembled step does it.
  SparseMatrix assembled(double c_stiff = kStiff, double c_stress = kStress, double c_mass = kMass) const {
    const LinkedVolume& volume = model.volume;
    volume.vertex_cells();
    const auto block = [&](CellId c, int a, int b) -> Mat3 {
      const auto ci = static_cast<std::size_t>(c);
      const Mat3& r = rotations[ci];
      Mat3 m = c_stiff * r * table.of_label(volume.cell_label(c)).stiffness.block<3, 3>(3 * a, 3 * b) * r.transpose();
      m.diagonal().array() += c_stress * stress_stiffness_coefficient(table, tension[ci], a, b);
      return m;
    };
    SparseMatrix a = make_vertex_block_pattern(volume);
    for (VertexId v = 0; v < volume.vertex_count(); ++v) gather_vertex_rows(volume, v, block, a);
    for (Eigen::Index i = 0; i < a.rows(); ++i) a.coeffRef(i, i) += c_mass * mass[i];
    FixedDofs held;
    held.fixed = fixed;
    held.value_mm = Vector::Zero(a.rows());
    Vector b = Vector::Zero(a.rows());
    eliminate_fixed_dofs(a, b, held);
    return a;
  }

  CorotatedSystemOperator op() const {
    CorotatedSystemOperator out;
    out.set_topology(model.volume, table);
    out.set_state(rotations, tension, kStiff, kStress, kMass, mass, fixed);
    return out;
  }
};

Vector probe(Eigen::Index n) {
  Vector x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = std::sin(0.37 * static_cast<double>(i)) + 0.2 * std::cos(1.3 * static_cast<double>(i));
  return x;
}

TEST(CorotatedSystemOperator, ProductEqualsTheAssembledSystemOnACutBodyUnderTension) {
  const Fixture f;
  ASSERT_GT(std::count(f.fixed.begin(), f.fixed.end(), std::uint8_t{1}), 20);
  std::size_t tense = 0;
  for (const Vec6& t : f.tension) tense += t.isZero() ? 0 : 1;
  ASSERT_EQ(tense, f.tension.size());  // every cell adds its stress stiffness
  const SparseMatrix a = f.assembled();
  const CorotatedSystemOperator op = f.op();
  ASSERT_EQ(op.rows(), a.rows());
  const Vector x = probe(a.rows());
  const Vector expected = a * x;
  Vector y;
  op.multiply(x, y);
  const double scale = expected.lpNorm<Eigen::Infinity>();
  ASSERT_GT(scale, 1.0);
  EXPECT_LE((y - expected).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
  // Fixed dofs: identity rows (and zero columns, which the comparison above covers).
  for (std::size_t i = 0; i < f.fixed.size(); ++i) {
    if (f.fixed[i] == 0) continue;
    EXPECT_EQ(y[static_cast<Eigen::Index>(i)], x[static_cast<Eigen::Index>(i)]);
  }
  // Single precision: float rounding of values of order 1e5 (mass term) and the products.
  Eigen::VectorXf y_single;
  op.multiply(Eigen::VectorXf(x.cast<float>()), y_single);
  EXPECT_LE((y_single.cast<double>() - expected).lpNorm<Eigen::Infinity>(), 3e-6 * scale);
  // Again with another vector: the work buffers are reused, not accumulated.
  const Vector x2 = 2.0 * x.reverse();
  op.multiply(x2, y);
  EXPECT_LE((y - a * x2).lpNorm<Eigen::Infinity>(), 1e-12 * 2.0 * scale);
}

// Cells held at all 8 corners (the studio's removed plugs and supports) feed identity rows only:
// the products leave them out and stay those of the assembled matrix, also when the held dofs
// change between states (the cells left out before are computed again, none is summed stale);
// the block diagonal of a held vertex is the identity without its sum.
TEST(CorotatedSystemOperator, CellsHeldAtEveryCornerAreLeftOutOfTheProducts) {
  Fixture f;
  const LinkedVolume& volume = f.model.volume;
  const std::vector<std::uint8_t> scattered = f.fixed;
  std::vector<std::uint8_t> slab = scattered;  // every vertex with x >= 4 cells held at all axes
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (volume.vertex_position_mm(v).x() >= volume.grid().origin_mm.x() + 4 * volume.grid().cell_size_mm - 1e-9)
      for (int i = 0; i < 3; ++i) slab[static_cast<std::size_t>(3 * v + i)] = 1;
  std::size_t free_cells = 0;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const auto& corners = volume.cell_vertices(c);
    free_cells += std::any_of(corners.begin(), corners.end(), [&](VertexId v) {
      const auto i = static_cast<std::size_t>(3 * v);
      return slab[i] == 0 || slab[i + 1] == 0 || slab[i + 2] == 0;
    }) ? 1 : 0;
  }
  ASSERT_LT(free_cells, static_cast<std::size_t>(volume.cell_count()));
  ASSERT_GT(free_cells, 0u);
  CorotatedSystemOperator op;
  op.set_topology(volume, f.table);
  const std::vector<std::uint8_t>* sequence[] = {&scattered, &slab, &scattered, &slab};
  for (const std::vector<std::uint8_t>* held : sequence) {
    f.fixed = *held;
    op.set_state(f.rotations, f.tension, kStiff, kStress, kMass, f.mass, f.fixed);
    EXPECT_EQ(op.computed_cells(), held == &slab ? free_cells : static_cast<std::size_t>(volume.cell_count()));
    const SparseMatrix a = f.assembled();
    const Vector x = probe(a.rows());
    const Vector expected = a * x;
    const double scale = expected.lpNorm<Eigen::Infinity>();
    Vector y;
    op.multiply(x, y);
    EXPECT_LE((y - expected).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
    Eigen::VectorXf y_single;
    op.multiply(Eigen::VectorXf(x.cast<float>()), y_single);
    EXPECT_LE((y_single.cast<double>() - expected).lpNorm<Eigen::Infinity>(), 3e-6 * scale);
    const Vector b = probe(a.rows()).reverse();
    Vector r;
    op.residual(b, x, r);
    EXPECT_LE((r - (b - expected)).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
    // The block diagonal's inverses: the identity on held vertices, as the assembled matrix's.
    const std::vector<Mat3> inverse = op.inverse_diagonal_blocks();
    const BlockJacobi jacobi = block_jacobi(a);
    ASSERT_EQ(inverse.size(), jacobi.inverse_blocks.size());
    for (std::size_t v = 0; v < inverse.size(); ++v)
      ASSERT_LE((inverse[v] - jacobi.inverse_blocks[v]).norm(), 1e-12 * jacobi.inverse_blocks[v].norm()) << "vertex " << v;
  }
}

TEST(CorotatedSystemOperator, BlockDiagonalAndAssemblyEqualTheAssembledSystem) {
  const Fixture f;
  const SparseMatrix a = f.assembled();
  const CorotatedSystemOperator op = f.op();
  const std::vector<Mat3> inverse = op.inverse_diagonal_blocks();
  const BlockJacobi expected = block_jacobi(a);
  ASSERT_EQ(inverse.size(), expected.inverse_blocks.size());
  double largest = 0;
  for (std::size_t v = 0; v < inverse.size(); ++v) {
    const double norm = expected.inverse_blocks[v].norm();
    largest = std::max(largest, (inverse[v] - expected.inverse_blocks[v]).norm() / norm);
  }
  EXPECT_LE(largest, 1e-12);
  const SparseMatrix assembled = op.assembled_matrix();
  ASSERT_EQ(assembled.rows(), a.rows());
  const Vector x = probe(a.rows());
  EXPECT_LE((assembled * x - a * x).lpNorm<Eigen::Infinity>(), 1e-12 * (a * x).lpNorm<Eigen::Infinity>());
  EXPECT_EQ(assembled.nonZeros(), a.nonZeros());  // the vertex block pattern of the cut body
}

// The smoother's step z = D^-1 (b - A x) in one pass with the product's per-vertex sum equals it
// from the assembled matrix, fixed dofs (identity rows) included, in double and in float.
TEST(CorotatedSystemOperator, JacobiResidualInOnePassEqualsItFromTheAssembledSystem) {
  const Fixture f;
  const SparseMatrix a = f.assembled();
  const CorotatedSystemOperator op = f.op();
  const std::vector<Mat3> inverse = op.inverse_diagonal_blocks();
  const Vector x = probe(a.rows());
  const Vector b = 0.5 * probe(a.rows()).reverse();
  const Vector r = b - a * x;
  Vector expected(a.rows());
  for (std::size_t v = 0; v < inverse.size(); ++v) {
    const auto i = 3 * static_cast<Eigen::Index>(v);
    expected.segment<3>(i) = inverse[v] * r.segment<3>(i);
  }
  const double scale = expected.lpNorm<Eigen::Infinity>();
  Vector z;
  op.jacobi_residual(inverse, b, x, z);
  EXPECT_LE((z - expected).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
  std::vector<Mat3f> single(inverse.size());
  for (std::size_t v = 0; v < inverse.size(); ++v) single[v] = inverse[v].cast<float>();
  Eigen::VectorXf z_single;
  op.jacobi_residual(single, Eigen::VectorXf(b.cast<float>()), Eigen::VectorXf(x.cast<float>()), z_single);
  // Float rounding of the product (values of order 1e5, as in the float product's test) and of D^-1.
  Eigen::VectorXf z_default;
  op.VertexOperator::jacobi_residual(single, Eigen::VectorXf(b.cast<float>()), Eigen::VectorXf(x.cast<float>()), z_default);
  EXPECT_LE((z_single - z_default).lpNorm<Eigen::Infinity>(), 1e-6f * static_cast<float>(scale));
  EXPECT_LE((z_single.cast<double>() - expected).lpNorm<Eigen::Infinity>(), 1e-4 * scale);
  // Sizes that do not fit are refused with both named.
  try {
    op.jacobi_residual(inverse, Vector(Vector::Zero(6)), x, z);
    ADD_FAILURE() << "a short right-hand side was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("right-hand side of 6 entries"), std::string::npos) << e.what();
  }
}

// The Chebyshev step d = c_d d + c_z D^-1 (b - A x), x += d in one pass with the product's
// per-vertex sum (x updated while the sum runs) equals the product, then a pass: in double and in
// float, fixed dofs included; wrong sizes are refused.
TEST(CorotatedSystemOperator, ChebyshevStepInOnePassEqualsTheProductThenAPass) {
  const Fixture f;
  const CorotatedSystemOperator op = f.op();
  const std::vector<Mat3> inverse = op.inverse_diagonal_blocks();
  const Vector b = 0.5 * probe(op.rows()).reverse();
  const Vector x0 = probe(op.rows());
  const Vector d0 = 0.01 * probe(op.rows()).cwiseAbs();
  Vector x = x0, d = d0, work;
  op.chebyshev_step(inverse, b, x, d, 0.3, 0.7, work);
  Vector x_ref = x0, d_ref = d0;
  op.VertexOperator::chebyshev_step(inverse, b, x_ref, d_ref, 0.3, 0.7, work);
  const double scale = d_ref.lpNorm<Eigen::Infinity>();
  ASSERT_GT(scale, 0.0);
  EXPECT_LE((d - d_ref).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
  EXPECT_LE((x - x_ref).lpNorm<Eigen::Infinity>(), 1e-12 * x_ref.lpNorm<Eigen::Infinity>());
  EXPECT_GT((x - x0).lpNorm<Eigen::Infinity>(), 0.1 * scale);  // it moved
  std::vector<Mat3f> single(inverse.size());
  for (std::size_t v = 0; v < inverse.size(); ++v) single[v] = inverse[v].cast<float>();
  Eigen::VectorXf xs = x0.cast<float>(), ds = d0.cast<float>(), xs_ref = xs, ds_ref = ds, works;
  const Eigen::VectorXf bs = b.cast<float>();
  op.chebyshev_step(single, bs, xs, ds, 0.3f, 0.7f, works);
  op.VertexOperator::chebyshev_step(single, bs, xs_ref, ds_ref, 0.3f, 0.7f, works);
  EXPECT_LE((ds - ds_ref).cast<double>().lpNorm<Eigen::Infinity>(), 1e-6 * scale);
  EXPECT_LE((ds.cast<double>() - d_ref).lpNorm<Eigen::Infinity>(), 1e-4 * scale);
  try {
    Eigen::VectorXd short_d = Vector::Zero(6);
    op.chebyshev_step(inverse, b, x, short_d, 0.3, 0.7, work);
    ADD_FAILURE() << "a short direction was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("direction of 6"), std::string::npos) << e.what();
  }
}

// The residual b - A x in one pass with the product's per-vertex sum equals it from the assembled
// matrix (fixed dofs: b - x), in double and in float.
TEST(CorotatedSystemOperator, ResidualInOnePassEqualsItFromTheAssembledSystem) {
  const Fixture f;
  const SparseMatrix a = f.assembled();
  const CorotatedSystemOperator op = f.op();
  const Vector x = probe(a.rows());
  const Vector b = 0.5 * probe(a.rows()).reverse();
  const Vector expected = b - a * x;
  const double scale = expected.lpNorm<Eigen::Infinity>();
  Vector r;
  op.residual(b, x, r);
  EXPECT_LE((r - expected).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
  Eigen::VectorXf r_single, r_default;
  op.residual(Eigen::VectorXf(b.cast<float>()), Eigen::VectorXf(x.cast<float>()), r_single);
  op.VertexOperator::residual(Eigen::VectorXf(b.cast<float>()), Eigen::VectorXf(x.cast<float>()), r_default);
  EXPECT_EQ(r_single, r_default);  // the same sums, subtracted in the same pass or the next
  EXPECT_LE((r_single.cast<double>() - expected).lpNorm<Eigen::Infinity>(), 1e-4 * scale);
  try {
    op.residual(Vector(Vector::Zero(6)), x, r);
    ADD_FAILURE() << "a short right-hand side was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("corotated system: right-hand side of 6 entries; expected {}", a.rows()));
  }
}

TEST(CorotatedSystemOperator, WithoutTensionItIsTheCorotatedStiffnessPlusMass) {
  const Fixture f;
  CorotatedSystemOperator op;
  op.set_topology(f.model.volume, f.table);
  const std::vector<std::uint8_t> free(f.fixed.size(), 0);
  op.set_state(f.rotations, {}, 1.0, 1.0, 0.0, f.mass, free);
  // A rigid translation lies in the null space of R K R^T.
  Vector x(op.rows());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = i % 3 == 0 ? 1.0 : (i % 3 == 1 ? -2.0 : 0.5);
  Vector y;
  op.multiply(x, y);
  EXPECT_LE(y.lpNorm<Eigen::Infinity>(), 1e-10 * f.table.per_material[0].stiffness.lpNorm<Eigen::Infinity>());
}

TEST(CorotatedSystemOperator, RefusesStateThatDoesNotFitItsTopology) {
  const Fixture f;
  CorotatedSystemOperator op;
  try {
    op.set_state(f.rotations, f.tension, 1, 1, 1, f.mass, f.fixed);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "corotated system: set_topology must come before set_state");
  }
  op.set_topology(f.model.volume, f.table);
  try {
    (void)op.inverse_diagonal_blocks();
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "corotated system: set_state must come before its block diagonal");
  }
  const std::vector<Mat3> short_rotations(f.rotations.begin(), f.rotations.end() - 1);
  try {
    op.set_state(short_rotations, f.tension, 1, 1, 1, f.mass, f.fixed);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              fmt::format("corotated system: {} rotations, {} tensions, {} masses and {} fixed flags; expected {} cells (tensions: "
                          "or none) and {} dofs",
                          short_rotations.size(), f.tension.size(), f.mass.size(), f.fixed.size(), f.rotations.size(), f.mass.size()));
  }
  op.set_state(f.rotations, f.tension, 1, 1, 1, f.mass, f.fixed);
  Vector y;
  try {
    op.multiply(Vector::Zero(6), y);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("corotated system: vector has 6 entries; expected {}", f.mass.size()));
  }
}

// The AVX-512 cell passes (float: two cells per register; double: one; both in corner modes)
// compute the portable passes' products: an odd cell count (the last cell alone), neighbours of
// different materials in one register, a cut, held dofs, with and without tension. All also meet
// the independently gathered matrix.
TEST(CorotatedSystemOperator, WideCellPassEqualsThePortableOne) {
  if (!avx512_cell_pass_supported()) GTEST_SKIP() << "this CPU has no AVX-512 F and DQ: only the portable pass runs";
  TissueModel model = test::make_box_model({7, 5, 3}, 1.5, 60.0, 0.42, [](const Vec3i& v) { return Label(v.x() % 3 == 1 ? 2 : 1); },
                                           {{Label{2}, Material{"stiff", 180.0, 0.3, 1100.0}}});
  model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
    const Vec3i v = model.volume.cell_voxel(c);
    return v.x() < 3 && v.y() < 2;
  }));
  ASSERT_EQ(model.volume.cell_count() % 2, 1);
  const ElementTable table = make_element_table(model);
  std::vector<Vec6> residual(static_cast<std::size_t>(model.volume.cell_count()));
  for (std::size_t c = 0; c < residual.size(); ++c) residual[c] << 15.0 + static_cast<double>(c % 7), 6.0, 1.0, 2.0, -0.5, 1.0;
  std::vector<Mat3> rotations;
  std::vector<Vec6> tension;
  cell_rotations_and_tension(model.volume, table, residual, test::turned_displacement(model.volume), rotations, tension);
  const Vector mass = lumped_mass(model, table);
  const std::vector<std::uint8_t> fixed = held_dofs(model.volume);
  for (const bool with_tension : {true, false}) {
    SCOPED_TRACE(with_tension ? "with tension" : "without tension");
    CorotatedSystemOperator op;
    op.set_topology(model.volume, table);
    EXPECT_TRUE(op.wide_cell_pass());  // the default where the CPU has it
    EXPECT_TRUE(op.mode_cell_pass());  // isotropic materials on cubes
    op.set_state(rotations, with_tension ? std::span<const Vec6>(tension) : std::span<const Vec6>(), kStiff, kStress, kMass, mass, fixed);
    const Eigen::VectorXf x = probe(op.rows()).cast<float>();
    Eigen::VectorXf wide, portable;
    op.multiply(x, wide);
    op.set_wide_cell_pass(false);
    op.multiply(x, portable);
    Vector exact;
    op.multiply(Vector(x.cast<double>()), exact);  // the portable double pass
    op.set_wide_cell_pass(true);
    Vector wide_exact;
    op.multiply(Vector(x.cast<double>()), wide_exact);
    const double scale = exact.lpNorm<Eigen::Infinity>();
    ASSERT_GT(scale, 1.0);
    // The double passes: the same operations in another order (and the held rows copied alike).
    EXPECT_LE((wide_exact - exact).lpNorm<Eigen::Infinity>(), 1e-13 * scale);
    EXPECT_LE((wide_exact - op.assembled_matrix() * Vector(x.cast<double>())).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
    // Float rounding in another order of the same operations: far below the 3e-6 both meet.
    EXPECT_LE((wide - portable).cast<double>().lpNorm<Eigen::Infinity>(), 1e-6 * scale);
    EXPECT_LE((wide.cast<double>() - exact).lpNorm<Eigen::Infinity>(), 3e-6 * scale);
    EXPECT_LE((portable.cast<double>() - exact).lpNorm<Eigen::Infinity>(), 3e-6 * scale);
    for (std::size_t i = 0; i < fixed.size(); ++i) {
      if (fixed[i] != 0) {
        EXPECT_EQ(wide[static_cast<Eigen::Index>(i)], x[static_cast<Eigen::Index>(i)]);
      }
    }
  }
}

// Element matrices without the corner-mode form (here an anisotropic material's) cannot take the
// AVX-512 passes: the portable pass runs, and its products are still the gathered matrix's.
TEST(CorotatedSystemOperator, ElementMatricesWithoutTheModeFormTakeThePortablePass) {
  TissueModel model = test::make_box_model({4, 3, 3}, 1.0, 60.0, 0.42, [](const Vec3i&) { return Label{1}; }, {});
  ElementTable table = make_element_table(model);
  Mat6 anisotropic = table.per_material[0].elasticity_kPa;
  anisotropic(0, 3) = anisotropic(3, 0) = 0.2 * anisotropic(3, 3);
  table.per_material[0].stiffness = hex8_stiffness(table.cell_size_mm, anisotropic);
  std::vector<Vec6> residual(static_cast<std::size_t>(model.volume.cell_count()), Vec6::Constant(3.0));
  std::vector<Mat3> rotations;
  std::vector<Vec6> tension;
  cell_rotations_and_tension(model.volume, table, residual, test::turned_displacement(model.volume), rotations, tension);
  const Vector mass = lumped_mass(model, table);
  const std::vector<std::uint8_t> fixed = held_dofs(model.volume);
  CorotatedSystemOperator op;
  op.set_topology(model.volume, table);
  op.set_state(rotations, tension, kStiff, kStress, kMass, mass, fixed);
  EXPECT_FALSE(op.mode_cell_pass());
  const Vector x = probe(op.rows());
  Vector y;
  op.multiply(x, y);
  const Vector gathered = op.assembled_matrix() * x;
  EXPECT_LE((y - gathered).lpNorm<Eigen::Infinity>(), 1e-12 * gathered.lpNorm<Eigen::Infinity>());
  Eigen::VectorXf y_single;
  op.multiply(Eigen::VectorXf(x.cast<float>()), y_single);
  EXPECT_LE((y_single.cast<double>() - gathered).lpNorm<Eigen::Infinity>(), 3e-6 * gathered.lpNorm<Eigen::Infinity>());
}

/// Largest relative difference of two preconditioned vectors.
double relative_difference(const Vector& a, const Vector& b) { return (a - b).norm() / b.norm(); }

// The V-cycle whose fine level applies the operator is the V-cycle on the assembled blocks: in
// float (to its rounding), after the switch to double (to 1e-12), and after a cut replaced the fine
// level from the operator instead of from the new matrix.
TEST(CorotatedSystemOperator, MultigridCycleOnTheOperatorIsTheCycleOnTheBlocks) {
  Fixture f;
  MultigridOptions options;
  options.coarsest_max_dofs = 60;
  options.weak_pieces.max_links = 0;  // a fine level applied without its matrix has no rows for them
  const SparseMatrix a = f.assembled();
  const CorotatedSystemOperator op = f.op();
  MultigridPreconditioner on_blocks = build_multigrid(a, f.model.volume, options);
  MultigridPreconditioner on_operator = build_multigrid(a, f.model.volume, options);
  ASSERT_GE(on_operator.levels().size(), 2u);
  on_operator.use_fine_operator(op, op.inverse_diagonal_blocks());
  EXPECT_TRUE(on_operator.uses_fine_operator());
  const Vector r = probe(a.rows());
  Vector z_blocks, z_operator;
  on_blocks.apply(r, z_blocks);
  on_operator.apply(r, z_operator);
  EXPECT_LT(relative_difference(z_operator, z_blocks), 1e-5);
  const BlockSparseMatrix<double> blocks = to_block_sparse<double>(a);
  on_blocks.use_double_precision(blocks);
  on_operator.use_double_precision(blocks);
  on_blocks.apply(r, z_blocks);
  on_operator.apply(r, z_operator);
  EXPECT_LT(relative_difference(z_operator, z_blocks), 1e-12);

  // A cut through the body's other half: both hierarchies keep their coarse levels.
  const VertexId before = f.model.volume.vertex_count();
  const CutReport report = f.model.volume.cut_links(test::faces_between(f.model.volume, [&](CellId c) {
    const Vec3i v = f.model.volume.cell_voxel(c);
    return v.x() >= 4 && v.y() >= 2 && v.y() < 4;
  }));
  const VertexId after = f.model.volume.vertex_count();
  ASSERT_GT(after, before);
  std::vector<VertexId> origins(static_cast<std::size_t>(after - before), kNone);
  for (const VertexSplit& split : report.splits)
    for (const VertexId v : split.created) origins[static_cast<std::size_t>(v - before)] = split.original;
  Fixture cut_state;  // the same construction on the cut topology (rotations, tension, mass, fixed)
  cut_state.model = f.model;
  cut_state.table = make_element_table(cut_state.model);
  cut_state.mass = lumped_mass(cut_state.model, cut_state.table);
  cut_state.fixed = held_dofs(cut_state.model.volume);
  std::vector<Vec6> residual(static_cast<std::size_t>(cut_state.model.volume.cell_count()), Vec6::Constant(3.0));
  cell_rotations_and_tension(cut_state.model.volume, cut_state.table, residual, test::turned_displacement(cut_state.model.volume),
                             cut_state.rotations, cut_state.tension);
  const SparseMatrix a_cut = cut_state.assembled();
  const CorotatedSystemOperator op_cut = cut_state.op();
  on_blocks.replace_fine_level(to_block_sparse<double>(a_cut), origins, options.smoother);
  on_operator.replace_fine_level(op_cut, op_cut.inverse_diagonal_blocks(), origins, options.smoother);
  EXPECT_EQ(on_operator.levels()[0].fixed, cut_state.fixed);
  EXPECT_NEAR(on_operator.levels()[0].smoother.lambda_max, on_blocks.levels()[0].smoother.lambda_max,
              1e-10 * on_blocks.levels()[0].smoother.lambda_max);
  const Vector r_cut = probe(a_cut.rows());
  on_blocks.apply(r_cut, z_blocks);
  on_operator.apply(r_cut, z_operator);
  EXPECT_LT(relative_difference(z_operator, z_blocks), 1e-12);
  // Sizes that do not fit are refused, naming them.
  try {
    on_operator.replace_fine_level(op_cut, op_cut.inverse_diagonal_blocks(), origins, options.smoother);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("multigrid: the new fine matrix has {} rows; expected {} ({} vertices and {} copies, 3 "
                                                 "dofs each)",
                                                 a_cut.rows(), 3 * (after + static_cast<VertexId>(origins.size())), after, origins.size()));
  }
}

// The hierarchy built for the operator from the start (the dynamic step's rebuilds) keeps no
// copy of the fine matrix and no fine weak pieces, and cycles as the hierarchy built on the blocks
// and then switched to the operator; a solver set up so solves exactly and takes later operators.
TEST(CorotatedSystemOperator, MultigridBuiltForTheOperatorCyclesAsTheOneSwitchedToIt) {
  const Fixture f;
  const LinkedVolume& volume = f.model.volume;
  MultigridOptions options;
  options.coarsest_max_dofs = 60;
  const SparseMatrix a = f.assembled();
  const BlockSparseMatrix<double> blocks = to_block_sparse<double>(a);
  const CorotatedSystemOperator op = f.op();
  MultigridPreconditioner switched = build_multigrid(blocks, volume, options);
  MultigridPreconditioner built = build_multigrid_for_operator(op, blocks, volume, options);
  ASSERT_GE(built.levels().size(), 2u);
  switched.use_fine_operator(op, op.inverse_diagonal_blocks());
  EXPECT_TRUE(built.uses_fine_operator());
  EXPECT_EQ(built.levels()[0].single.blocks.blocks(), 0u);
  EXPECT_EQ(built.levels()[0].weak_pieces.piece_count(), 0);
  EXPECT_EQ(built.levels()[0].fixed, f.fixed);
  EXPECT_NEAR(built.levels()[0].smoother.lambda_max, switched.levels()[0].smoother.lambda_max,
              1e-6 * switched.levels()[0].smoother.lambda_max);
  const Vector r = probe(a.rows());
  Vector z_switched, z_built;
  switched.apply(r, z_switched);
  built.apply(r, z_built);
  EXPECT_LT(relative_difference(z_built, z_switched), 1e-5);
  // A rebuild continues the fine smoother's estimate of the hierarchy it replaces: closer to the
  // spectrum's top than the cold start, and never below the old bound.
  ChebyshevOptions exact = options.smoother;
  exact.power_iterations = 400;
  const double top = make_chebyshev_smoother<double>(op, op.inverse_diagonal_blocks(), exact).lambda_max;
  const std::vector<VertexId> no_copies;
  const MultigridPreconditioner rebuilt =
      build_multigrid_for_operator(op, blocks, volume, options, ChebyshevWarmStart{&built.levels()[0].smoother, &no_copies});
  const double cold = built.levels()[0].smoother.lambda_max, warm = rebuilt.levels()[0].smoother.lambda_max;
  EXPECT_GE(warm, cold);
  EXPECT_LT(std::abs(warm - top), std::abs(cold - top));

  SolveSettings settings;
  settings.relative_tolerance = 1e-10;
  const auto solver = make_multigrid_cg_solver(settings, options);
  ASSERT_TRUE(solver->setup_operator(op, blocks, volume));
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> direct{Eigen::SparseMatrix<double>(a)};
  const Vector expected = direct.solve(r);
  Vector x = Vector::Zero(a.rows());
  EXPECT_TRUE(solver->solve(r, x).converged);
  EXPECT_LT((x - expected).norm(), 1e-8 * expected.norm());
  EXPECT_TRUE(solver->update_operator(op, volume));  // the levels are kept for the next state
  // One level (the whole body factorized): the factor preconditions, CG multiplies with the blocks.
  MultigridOptions one_level = options;
  one_level.coarsest_max_dofs = 1 << 20;
  const auto direct_solver = make_multigrid_cg_solver(settings, one_level);
  ASSERT_TRUE(direct_solver->setup_operator(op, blocks, volume));
  x.setZero();
  const SolveReport report = direct_solver->solve(r, x);
  EXPECT_LE(report.iterations, 2);  // an exact preconditioner: one iteration and one of rounding
  EXPECT_LT((x - expected).norm(), 1e-8 * expected.norm());
  EXPECT_FALSE(direct_solver->update_operator(op, volume));  // it needs the assembled values

  const BlockSparseMatrix<double> too_small = to_block_sparse<double>(Fixture().assembled().topLeftCorner(a.rows() - 3, a.rows() - 3));
  try {
    (void)build_multigrid_for_operator(op, too_small, volume, options);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("multigrid: the fine operator has {} rows and {} fixed flags; its assembled matrix has {} rows",
                                                 a.rows(), a.rows(), a.rows() - 3));
  }
  // The solver refuses the same before it drops anything: its levels still solve.
  try {
    (void)solver->setup_operator(op, too_small, volume);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              fmt::format("multigrid: the block copy of the operator has {} rows; the operator has {}", a.rows() - 3, a.rows()));
  }
  x.setZero();
  EXPECT_TRUE(solver->solve(r, x).converged);
  EXPECT_LT((x - expected).norm(), 1e-8 * expected.norm());
}

// A multigrid set up for one matrix and then given a very different one as an operator (turned
// cells, 40x the stiffness, a tenth of the mass) exceeds its stale-solve budget, assembles the
// operator and rebuilds mid-solve: the answer is still the exact one, and a later operator update
// is taken again.
TEST(CorotatedSystemOperator, MultigridRebuildsMidSolveFromTheOperator) {
  const Fixture f;
  const LinkedVolume& volume = f.model.volume;
  MultigridOptions options;
  options.coarsest_max_dofs = 60;  // two levels at least on this small body
  options.stale_solve_rebuild_factor = 1e-9;  // a stale solve may take 10 iterations
  SolveSettings settings;
  settings.relative_tolerance = 1e-10;
  const auto solver = make_multigrid_cg_solver(settings, options);
  const std::vector<Mat3> unturned(f.rotations.size(), Mat3::Identity());
  CorotatedSystemOperator first;
  first.set_topology(volume, f.table);
  first.set_state(unturned, {}, 1.0, 0.0, kMass, f.mass, f.fixed);
  SparseMatrix a = first.assembled_matrix();
  solver->setup(a, volume);
  const Vector b = probe(a.rows());
  Vector x = Vector::Zero(a.rows());
  const SolveReport baseline = solver->solve(b, x);
  ASSERT_TRUE(baseline.converged);
  CorotatedSystemOperator second;
  second.set_topology(volume, f.table);
  second.set_state(f.rotations, f.tension, 40.0, 40.0, 0.1 * kMass, f.mass, f.fixed);
  ASSERT_TRUE(solver->update_operator(second, volume));
  x.setZero();
  const SolveReport report = solver->solve(b, x);
  EXPECT_TRUE(report.converged);
  EXPECT_GT(report.iterations, 10);  // the stale budget ran out: rebuilt on the way
  const SparseMatrix exact = f.assembled(40.0, 40.0, 0.1 * kMass);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> direct{Eigen::SparseMatrix<double>(exact)};
  const Vector expected = direct.solve(b);
  EXPECT_LT((x - expected).norm(), 1e-8 * expected.norm());
  ASSERT_TRUE(solver->update_operator(second, volume));
  x.setZero();
  EXPECT_TRUE(solver->solve(b, x).converged);
  EXPECT_LT((x - expected).norm(), 1e-8 * expected.norm());
}

// CG with its iterations' products in single precision (SolveSettings::single_precision_products,
// what the multigrid uses for the dynamic step at its loose tolerance): at 1e-6 the solution of
// the double products; at any tolerance the residual it reports is the true one, in double, and
// "converged" means that one met the tolerance.
TEST(CorotatedSystemOperator, CgWithSinglePrecisionProductsReportsTheTrueResidual) {
  const Fixture f;
  const CorotatedSystemOperator op = f.op();
  const SparseMatrix a = f.assembled();
  BlockJacobi jacobi;
  jacobi.inverse_blocks = op.inverse_diagonal_blocks();
  Vector b = probe(a.rows()).reverse();
  for (std::size_t i = 0; i < f.fixed.size(); ++i)
    if (f.fixed[i] != 0) b[static_cast<Eigen::Index>(i)] = 0;
  for (const double tolerance : {1e-6, 1e-13}) {
    SCOPED_TRACE(fmt::format("tolerance {}", tolerance));
    SolveSettings settings;
    settings.relative_tolerance = tolerance;
    Vector x_double = Vector::Zero(a.rows()), x_single = Vector::Zero(a.rows());
    const SolveReport in_double = preconditioned_cg(op, b, x_double, jacobi, settings);
    settings.single_precision_products = true;
    const SolveReport in_single = preconditioned_cg(op, b, x_single, jacobi, settings);
    EXPECT_TRUE(in_double.converged);
    const double true_residual = (b - a * x_single).norm() / b.norm();
    // Both in double (the operator's product against the assembled CSR): they differ by double
    // rounding only; a float product would be off by ~1e-7 of ||A x|| / ||b||.
    EXPECT_NEAR(in_single.relative_residual, true_residual, 0.01 * true_residual + 1e-15);
    EXPECT_EQ(in_single.converged, true_residual <= tolerance);
    if (tolerance >= 1e-6) {
      EXPECT_TRUE(in_single.converged);
      EXPECT_LT((x_single - x_double).norm(), 1e-5 * x_double.norm());
    }
  }
}

// The step with the operator and the step with the assembled matrix solve the same system: a
// stressed plate held at one end, cut three times mid-simulation, to a tight tolerance.
TEST(CorotatedSystemOperator, DynamicsStepsWithItFollowTheAssembledSteps) {
  const TissueModel uncut = test::make_box_model({24, 12, 3}, 1.0, 80.0, 0.4);
  Vec6 stress;
  stress << 20.0, 10.0, 0, 4.0, 0, 0;
  const std::vector<Vec6> field(static_cast<std::size_t>(uncut.volume.cell_count()), stress);
  const auto run = [&](bool matrix_free, int& operator_steps) {
    TissueModel model = uncut;
    DynamicsSettings settings = test::held_plate_settings(model.volume);
    settings.matrix_free = matrix_free;
    Dynamics sim(model, field, settings);
    for (int i = 0; i < 3; ++i) sim.step(1e-3);
    for (const int depth : {5, 9}) {
      sim.topology_changed(test::cut_plate_slit(model, depth));
      for (int i = 0; i < 4; ++i) sim.step(1e-3);
    }
    // A third cut, then past the multigrid's 64 stale updates: the rebuild assembles on the block
    // pattern patched for the rows all three cuts touched.
    sim.topology_changed(model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
      const Vec3i& v = model.volume.cell_voxel(c);
      return v.x() >= 16 && v.x() < 19 && v.y() >= 4 && v.y() < 7;
    })));
    for (int i = 0; i < 60; ++i) sim.step(1e-3);
    operator_steps = sim.matrix_free_steps();
    return sim.displacement();
  };
  int with_operator = 0, assembled = 0;
  const Vector free = run(true, with_operator);
  const Vector reference = run(false, assembled);
  EXPECT_EQ(assembled, 0);
  // 71 steps, all with the operator: cuts included, and the first step and the multigrid's
  // rebuilds (when its iterations grow) too, which set up from the assembled blocks and apply
  // the operator (LinearSolver::setup_operator; 65 operator steps before it).
  EXPECT_EQ(with_operator, 71);
  ASSERT_EQ(free.size(), reference.size());
  ASSERT_GT(reference.norm(), 0.0);
  EXPECT_LT((free - reference).norm() / reference.norm(), 1e-8);
}

// A plate held over its first two cell layers (x <= 2 mm: 72 cells held at every corner): steps
// with the operator leave those cells' rotations, tensions and forces out after the first step
// on each topology, and still follow the assembled steps (which compute every cell) through two
// cuts, one of them through the held cells.
TEST(CorotatedSystemOperator, DynamicsStepsLeaveOutCellsHeldAtEveryCornerAndFollowTheAssembledSteps) {
  const TissueModel uncut = test::make_box_model({24, 12, 3}, 1.0, 80.0, 0.4);
  Vec6 stress;
  stress << 20.0, 10.0, 0, 4.0, 0, 0;
  const std::vector<Vec6> field(static_cast<std::size_t>(uncut.volume.cell_count()), stress);
  const auto cells = static_cast<std::size_t>(uncut.volume.cell_count());
  constexpr std::size_t kHeldCells = 2 * 12 * 3;
  const auto run = [&](bool matrix_free, std::vector<std::size_t>& computed) {
    TissueModel model = uncut;
    DynamicsSettings settings = test::held_plate_settings(model.volume);
    settings.fixed_vertices.clear();
    for (VertexId v = 0; v < model.volume.vertex_count(); ++v)
      if (model.volume.vertex_position_mm(v).x() < 2.0 + 1e-9) settings.fixed_vertices.push_back(v);
    settings.matrix_free = matrix_free;
    Dynamics sim(model, field, settings);
    const auto step = [&] {
      sim.step(1e-3);
      computed.push_back(sim.cells_in_last_step());
    };
    for (int i = 0; i < 3; ++i) step();
    for (const int depth : {5, 9}) {
      sim.topology_changed(test::cut_plate_slit(model, depth));
      for (int i = 0; i < 4; ++i) step();
    }
    return sim.displacement();
  };
  std::vector<std::size_t> with_operator, assembled;
  const Vector free = run(true, with_operator);
  const Vector reference = run(false, assembled);
  // Every cell on each topology's first step, the cells with a free corner after it.
  const std::size_t all = cells, some = cells - kHeldCells;
  EXPECT_EQ(with_operator, (std::vector<std::size_t>{all, some, some, all, some, some, some, all, some, some, some}));
  EXPECT_EQ(assembled, std::vector<std::size_t>(11, all));
  ASSERT_EQ(free.size(), reference.size());
  ASSERT_GT(reference.norm(), 0.0);
  EXPECT_LT((free - reference).norm() / reference.norm(), 1e-8);
}

}  // namespace
}  // namespace cleave
