// The equilibration's one-point stiffness Kc applied cell by cell (CentrePointStiffness): equal to
// its assembled matrix on a layered body with held vertices, blind to rigid and hourglass motions,
// its compatible stress equal to D Bc u_e cell by cell, and sizes checked with named errors.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fmt/format.h>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/stress/centre_point_stiffness.hpp"
#include "stress_test_models.hpp"

namespace cleave {
namespace {

/// The abdomen (skin, fat, muscle: three materials) at 24 x 8 x 16 cells.
TissueModel small_abdomen() {
  ShapeResolution resolution;
  resolution.cells = Vec3i(24, 8, 16);
  return test::builtin_model("abdomen", resolution);
}

/// Held: the vertices of the lowest x layer.
std::vector<std::uint8_t> held_lowest_x(const LinkedVolume& volume) {
  std::vector<std::uint8_t> held(3 * static_cast<std::size_t>(volume.vertex_count()), 0);
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (volume.vertex_grid_corner(v).x() == 0)
      for (int i = 0; i < 3; ++i) held[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(i)] = 1;
  return held;
}

TEST(CentrePointStiffness, TheProductEqualsTheAssembledMatrixWithHeldDofs) {
  const TissueModel model = small_abdomen();
  const ElementTable table = make_element_table(model);
  ASSERT_GE(table.per_material.size(), 2u);
  const std::vector<std::uint8_t> held = held_lowest_x(model.volume);
  const CentrePointStiffness kc(model.volume, table, held);
  const SparseMatrix a = kc.assembled();
  EXPECT_LT(SparseMatrix(a - SparseMatrix(a.transpose())).cwiseAbs().sum(), 1e-12 * a.cwiseAbs().sum());

  const Vector x = Vector::Random(kc.rows());
  Vector y;
  kc.multiply(x, y);
  const Vector expected = a * x;
  EXPECT_LT((y - expected).norm(), 1e-13 * expected.norm());
  for (std::size_t d = 0; d < held.size(); ++d) {  // identity rows
    if (!held[d]) continue;
    EXPECT_EQ(y[static_cast<Eigen::Index>(d)], x[static_cast<Eigen::Index>(d)]) << d;
  }

  const Vector b = Vector::Random(kc.rows());
  Vector r;
  kc.residual(b, x, r);
  EXPECT_LT((r - (b - expected)).norm(), 1e-13 * expected.norm());
}

// One-point quadrature sees no strain in a rigid motion nor in the hourglass modes
// u_x = (-1)^(j+k) f(i): the products vanish (up to rounding of the rotation's linear field).
TEST(CentrePointStiffness, RigidAndHourglassMotionsCostNothing) {
  const TissueModel model = small_abdomen();
  const std::vector<std::uint8_t> free(3 * static_cast<std::size_t>(model.volume.vertex_count()), 0);
  const CentrePointStiffness kc(model.volume, make_element_table(model), free);
  Vector rigid(kc.rows()), hourglass(kc.rows()), stretch(kc.rows());
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v) {
    const Vec3 p = model.volume.vertex_position_mm(v);
    const Vec3i g = model.volume.vertex_grid_corner(v);
    rigid.segment<3>(3 * v) = Vec3(0.3, -0.1, 0.2) + Vec3(0.01, -0.02, 0.015).cross(p);
    hourglass.segment<3>(3 * v) = Vec3(((g.y() + g.z()) % 2 == 0 ? 1.0 : -1.0) * std::sin(0.3 * g.x()), 0.0, 0.0);
    stretch.segment<3>(3 * v) = Vec3(0.01 * p.x(), 0.0, 0.0);
  }
  Vector y;
  kc.multiply(stretch, y);
  const double scale = y.norm();
  ASSERT_GT(scale, 0.0);
  kc.multiply(rigid, y);
  EXPECT_LT(y.norm(), 1e-12 * scale * rigid.norm() / stretch.norm());
  kc.multiply(hourglass, y);
  EXPECT_LT(y.norm(), 1e-12 * scale * hourglass.norm() / stretch.norm());
}

TEST(CentrePointStiffness, TheCompatibleStressIsDBcOfTheCellDisplacement) {
  const TissueModel model = small_abdomen();
  const ElementTable table = make_element_table(model);
  const std::vector<std::uint8_t> free(3 * static_cast<std::size_t>(model.volume.vertex_count()), 0);
  const CentrePointStiffness kc(model.volume, table, free);
  const Vector u = Vector::Random(kc.rows());
  std::vector<Vec6> stress(static_cast<std::size_t>(model.volume.cell_count()), Vec6::Constant(2.0));
  kc.add_stress(u, stress);
  const Mat6x24 bc = hex8_strain_matrix(Vec3::Constant(0.5), model.volume.grid().cell_size_mm);
  double worst = 0, largest = 0;
  for (CellId c = 0; c < model.volume.cell_count(); ++c) {
    Vec24 ue;
    const auto& corners = model.volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * corners[static_cast<std::size_t>(a)]);
    const Vec6 expected = Vec6::Constant(2.0) + table.of_label(model.volume.cell_label(c)).elasticity_kPa * (bc * ue);
    worst = std::max(worst, (stress[static_cast<std::size_t>(c)] - expected).cwiseAbs().maxCoeff());
    largest = std::max(largest, expected.cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-13 * largest);
}

TEST(CentrePointStiffness, WrongSizesAreNamed) {
  const TissueModel model = small_abdomen();
  const ElementTable table = make_element_table(model);
  const auto dofs = 3 * static_cast<std::size_t>(model.volume.vertex_count());
  try {
    CentrePointStiffness(model.volume, table, std::vector<std::uint8_t>(5, 0));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("centre-point stiffness: 5 held-dof flags; expected one per dof ({})", dofs));
  }
  const std::vector<std::uint8_t> free(dofs, 0);
  const CentrePointStiffness kc(model.volume, table, free);
  Vector y;
  try {
    kc.multiply(Vector::Zero(7), y);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("centre-point stiffness: vector has 7 entries; expected {}", dofs));
  }
  std::vector<Vec6> too_few(3, Vec6::Zero());
  try {
    kc.add_stress(Vector::Zero(static_cast<Eigen::Index>(dofs)), too_few);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              fmt::format("centre-point stiffness: 3 cell stresses; expected one per cell ({})", model.volume.cell_count()));
  }
}

}  // namespace
}  // namespace cleave
