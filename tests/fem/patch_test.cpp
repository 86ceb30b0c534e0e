// Patch tests: linear fields are reproduced exactly, and T applied to a uniform stress gives the
// surface traction at the boundary (also on faces a cut created) and nothing inside.
#include <gtest/gtest.h>

#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/fem/residual_stress_forces.hpp"
#include "cleave/fem/solve_static.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

bool on_box_boundary(const Vec3& p, const Vec3& extent) {
  constexpr double kTol = 1e-9;
  return (p.array() < kTol).any() || (p.array() > extent.array() - kTol).any();
}

TEST(PatchTest, LinearDisplacementFieldIsReproducedInside) {
  const TissueModel model = test::make_box_model({5, 4, 4}, 1.5, 80.0, 0.4);
  const LinkedVolume& volume = model.volume;
  Mat3 gradient;
  gradient << 0.01, -0.004, 0.002,  //
      0.003, -0.006, 0.005,         //
      -0.002, 0.001, 0.008;
  const Vec3 offset{0.1, -0.2, 0.05};
  const auto linear = [&](const Vec3& x) -> Vec3 { return gradient * x + offset; };

  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.settings.relative_tolerance = 1e-12;
  const Vec3 extent = volume.grid().extent_mm();
  int interior = 0;
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    if (on_box_boundary(volume.vertex_position_mm(v), extent)) {
      options.fixed_vertices.push_back(v);
      options.fixed_displacement_mm.push_back(linear(volume.vertex_position_mm(v)));
    } else {
      ++interior;
    }
  }
  ASSERT_EQ(interior, 4 * 3 * 3);
  const StaticResult r = solve_static(model, {}, options);
  const double scale = linear(extent).norm();
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    EXPECT_LT((r.displacement_mm[static_cast<std::size_t>(v)] - linear(volume.vertex_position_mm(v))).norm(), 1e-10 * scale)
        << "vertex " << v;
}

/// sigma n times a quarter of the face area for each corner of every face without an uncut link.
Vector expected_traction_forces(const LinkedVolume& volume, const Vec6& stress) {
  const double h = volume.grid().cell_size_mm;
  const Mat3 s = from_voigt(stress);
  Vector f = Vector::Zero(3 * static_cast<Eigen::Index>(volume.vertex_count()));
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (Face face = 0; face < kFaceCount; ++face) {
      if (volume.linked(c, face)) continue;
      const Vec3 normal = face_step(face).cast<double>();
      for (const int corner : face_corners(face)) f.segment<3>(3 * volume.corner_vertex(c, corner)) += s * normal * (h * h / 4);
    }
  return f;
}

TEST(PatchTest, UniformStressGivesZeroInsideAndSurfaceTractionOnTheBoundary) {
  TissueModel model = test::make_box_model({4, 3, 3}, 2.0);
  Vec6 stress;
  stress << 20.0, 10.0, -5.0, 3.0, -2.0, 1.5;  // kPa
  const auto check = [&](const char* when) {
    const LinkedVolume& volume = model.volume;
    const std::vector<Vec6> field(static_cast<std::size_t>(volume.cell_count()), stress);
    const Vector f = residual_stress_forces(volume, field);
    const Vector expected = expected_traction_forces(volume, stress);
    int zero_vertices = 0;
    for (VertexId v = 0; v < volume.vertex_count(); ++v) {
      EXPECT_LT((f.segment<3>(3 * v) - expected.segment<3>(3 * v)).norm(), 1e-12 * stress.norm()) << when << " vertex " << v;
      if (expected.segment<3>(3 * v).isZero()) ++zero_vertices;
    }
    return zero_vertices;
  };
  // Uncut: the interior vertices are the 3 x 2 x 2 grid corners not on the box surface.
  EXPECT_EQ(check("uncut"), 3 * 2 * 2);
  // A cut through the middle plane x = 4 mm creates two new free faces; their vertices now carry traction.
  const auto left = [&](CellId c) { return model.volume.cell_voxel(c).x() < 2; };
  model.volume.cut_links(test::faces_between(model.volume, left));
  ASSERT_EQ(model.volume.component_count(), 2);
  EXPECT_EQ(check("cut"), 2 * (1 * 2 * 2));
}

// The deformation gradient at a cell's centre (what the corotation turns by) is exact for an
// affine displacement, and equals I + sum_a u_a (grad N_a)^T from the shape functions for any.
TEST(PatchTest, CentreDeformationGradientOfAnAffineAndOfAnyDisplacement) {
  const double h_mm = 2.5;
  Mat3 g;
  g << 0.01, -0.2, 0.03, 0.15, -0.02, 0.4, -0.05, 0.07, 0.11;
  const Vec3 shift(1.0, -2.0, 0.5);
  Vec24 affine, any;
  Eigen::Matrix<double, 8, 3> gradients;  // dN_a/dx at the centre
  for (int a = 0; a < 8; ++a) {
    const Vec3 corner = h_mm * Vec3((a & 1) ? 1.0 : 0.0, ((a >> 1) & 1) ? 1.0 : 0.0, ((a >> 2) & 1) ? 1.0 : 0.0);
    affine.segment<3>(3 * a) = g * corner + shift;
    for (int i = 0; i < 3; ++i) any[3 * a + i] = std::sin(1.7 * a + 0.9 * i);
    for (int j = 0; j < 3; ++j) gradients(a, j) = (((a >> j) & 1) ? 1.0 : -1.0) / (4.0 * h_mm);
  }
  EXPECT_LE((hex8_center_deformation_gradient(affine, h_mm) - (Mat3::Identity() + g)).norm(), 1e-14);
  Mat3 expected = Mat3::Identity();
  for (int a = 0; a < 8; ++a) expected += any.segment<3>(3 * a) * gradients.row(a);
  EXPECT_LE((hex8_center_deformation_gradient(any, h_mm) - expected).norm(), 1e-14);
}

}  // namespace
}  // namespace cleave
