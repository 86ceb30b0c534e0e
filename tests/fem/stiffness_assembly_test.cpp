// Global operators: symmetry, rigid null space per piece, mass totals, and the incremental
// update after cuts equals a fresh assembly.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "cleave/core/units.hpp"
#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/rigid_supports.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

double max_abs(const SparseMatrix& m) {
  double out = 0;
  for (Eigen::Index r = 0; r < m.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(m, r); it; ++it) out = std::max(out, std::abs(it.value()));
  return out;
}

/// Translations and infinitesimal rotations of one component (others at rest), 6 columns.
Eigen::MatrixXd rigid_modes(const LinkedVolume& volume, int component) {
  const std::vector<int> comp = vertex_components(volume);
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(3 * volume.vertex_count(), 6);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    if (comp[static_cast<std::size_t>(v)] != component) continue;
    const Vec3 x = volume.vertex_position_mm(v);
    for (int k = 0; k < 3; ++k) {
      modes(3 * v + k, k) = 1.0;
      modes.block<3, 1>(3 * v, 3 + k) = Vec3::Unit(k).cross(x);
    }
  }
  return modes;
}

TEST(StiffnessAssembly, SymmetricWithRigidNullSpaceOfEveryPiece) {
  TissueModel model = test::make_box_model({5, 4, 3}, 2.0);
  const auto plug = [&](CellId c) {
    const Vec3i v = model.volume.cell_voxel(c);
    return v.x() >= 1 && v.x() <= 2 && v.y() >= 1 && v.y() <= 2;
  };
  model.volume.cut_links(test::faces_between(model.volume, plug));
  ASSERT_EQ(model.volume.component_count(), 2);
  const SparseMatrix k = assemble_stiffness(model);
  const double scale = max_abs(k);
  EXPECT_LT(max_abs(SparseMatrix(k - SparseMatrix(k.transpose()))), 1e-12 * scale);
  for (int piece = 0; piece < 2; ++piece) {
    const Eigen::MatrixXd modes = rigid_modes(model.volume, piece);
    EXPECT_LT((k * modes).cwiseAbs().maxCoeff(), 1e-10 * scale * 20.0) << "piece " << piece;
  }
  // K is positive semi-definite with exactly 12 zero eigenvalues (two free pieces).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig{Eigen::MatrixXd(k)};
  int zero = 0;
  for (Eigen::Index i = 0; i < eig.eigenvalues().size(); ++i) {
    EXPECT_GT(eig.eigenvalues()[i], -1e-10 * scale);
    if (eig.eigenvalues()[i] < 1e-9 * scale) ++zero;
  }
  EXPECT_EQ(zero, 12);
}

TEST(StiffnessAssembly, SameMaterialCellsShareTheElementStiffness) {
  // One cell: K equals K^e of its material with rows in corner order.
  const TissueModel model = test::make_box_model({1, 1, 1}, 3.0, 50.0, 0.3);
  const Mat24 ke = hex8_stiffness(3.0, isotropic_elasticity(50.0, 0.3));
  const Eigen::MatrixXd k{assemble_stiffness(model)};
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(24, 24);
  for (int a = 0; a < 8; ++a)
    for (int b = 0; b < 8; ++b)
      expected.block<3, 3>(3 * model.volume.corner_vertex(0, a), 3 * model.volume.corner_vertex(0, b)) = ke.block<3, 3>(3 * a, 3 * b);
  EXPECT_LT((k - expected).cwiseAbs().maxCoeff(), 1e-12 * ke.cwiseAbs().maxCoeff());
}

TEST(StiffnessAssembly, LumpedMassIsTheBodyMassBeforeAndAfterCuts) {
  TissueModel model = test::make_box_model({4, 3, 2}, 2.5);
  const double expected_kg = units::density_kg_per_mm3(1000.0) * 24 * 2.5 * 2.5 * 2.5;
  EXPECT_NEAR(lumped_mass(model).sum() / 3.0, expected_kg, 1e-12 * expected_kg);
  model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) { return model.volume.cell_voxel(c).x() < 2; }));
  EXPECT_NEAR(lumped_mass(model).sum() / 3.0, expected_kg, 1e-12 * expected_kg);
}

TEST(StiffnessAssembly, UpdateAfterCutsEqualsFreshAssembly) {
  // Two materials (label 2 for z >= 1), so the update must pick each cell's own K^e.
  TissueModel model = test::make_box_model({6, 5, 3}, 2.0, 80.0, 0.4, [](const Vec3i& v) { return Label(v.z() >= 1 ? 2 : 1); },
                                           {{Label{2}, Material{"stiff", 200.0, 0.3, 1100.0}}});
  SparseMatrix k = assemble_stiffness(model);
  const VertexId before = model.volume.vertex_count();
  // First cut frees the corner block x < 3, y < 3 cells; the second frees the slab y >= 4.
  const CutReport first = model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
    const Vec3i v = model.volume.cell_voxel(c);
    return v.x() < 3 && v.y() < 3;
  }));
  ASSERT_GT(model.volume.vertex_count(), before);
  update_stiffness_after_cut(model, first, k);
  const SparseMatrix fresh1 = assemble_stiffness(model);
  ASSERT_EQ(k.rows(), fresh1.rows());
  EXPECT_EQ(max_abs(SparseMatrix(k - fresh1)), 0.0);
  const CutReport second = model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
    return model.volume.cell_voxel(c).y() >= 4;
  }));
  update_stiffness_after_cut(model, second, k);
  const SparseMatrix fresh2 = assemble_stiffness(model);
  ASSERT_EQ(k.rows(), fresh2.rows());
  EXPECT_EQ(k.nonZeros(), fresh2.nonZeros());
  EXPECT_EQ(max_abs(SparseMatrix(k - fresh2)), 0.0);
  EXPECT_EQ(model.volume.component_count(), 3);
}

}  // namespace
}  // namespace cleave
