// The stiffness damping force beta K_R v, which the dynamics evaluates per cell (R K^e R^T v_e,
// in Dynamics::internal_forces beside the elastic force) instead of multiplying an assembled K_R,
// equals the product with the assembled corotated stiffness, to rounding.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "cleave/fem/corotation.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/fem/vertex_block_matrix.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

TEST(DynamicsDampingForce, PerCellProductEqualsTheAssembledCorotatedStiffness) {
  const TissueModel model = test::make_box_model({5, 3, 2}, 1.5, 40.0, 0.42);
  const LinkedVolume& volume = model.volume;
  const auto n = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  // A deformed, rotated state and a velocity without structure.
  const Mat3 turn = Eigen::AngleAxisd(0.7, Vec3(0.2, -1.0, 0.4).normalized()).toRotationMatrix();
  Vector u(n), v(n);
  for (VertexId i = 0; i < volume.vertex_count(); ++i) {
    const Vec3 x = volume.vertex_position_mm(i);
    const Vec3 wobble(0.05 * std::sin(1.3 * x.y()), 0.04 * std::cos(0.7 * x.x()), 0.03 * std::sin(x.x() + x.z()));
    u.segment<3>(3 * i) = turn * (x + wobble) - x;
    v.segment<3>(3 * i) = Vec3(std::sin(0.3 * i), std::cos(0.11 * i), std::sin(0.05 * i + 1.0));
  }
  std::vector<Mat3> rotations;
  cell_rotations(volume, u, rotations);
  const ElementTable table = make_element_table(model);
  SparseMatrix k = make_vertex_block_pattern(volume);
  volume.vertex_cells();
  const auto block = [&](CellId c, int a, int b) -> Mat3 {
    const Mat3& r = rotations[static_cast<std::size_t>(c)];
    return r * table.of_label(volume.cell_label(c)).stiffness.block<3, 3>(3 * a, 3 * b) * r.transpose();
  };
  for (VertexId i = 0; i < volume.vertex_count(); ++i) gather_vertex_rows(volume, i, block, k);
  const Vector expected = k * v;
  // The per-cell form, written out as the dynamics does it.
  Vector per_cell = Vector::Zero(n);
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Mat3& r = rotations[static_cast<std::size_t>(c)];
    const Vec24 ve = cell_displacement(volume, c, v);
    Vec24 local;
    for (int a = 0; a < kCornerCount; ++a) local.segment<3>(3 * a) = r.transpose() * ve.segment<3>(3 * a);
    local = table.of_label(volume.cell_label(c)).stiffness * local;
    const auto& corners = volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a)
      per_cell.segment<3>(3 * corners[static_cast<std::size_t>(a)]) += r * local.segment<3>(3 * a);
  }
  EXPECT_LT((per_cell - expected).lpNorm<Eigen::Infinity>(), 1e-12 * expected.lpNorm<Eigen::Infinity>());
}

}  // namespace
}  // namespace cleave
