// Removing the rigid part of a displacement (RigidMotionRemover, the static solver's last step on
// free pieces): a rigid motion is removed exactly, only from the listed pieces, what is left has
// no weighted mean translation or rotation, and bad input is named.
#include <gtest/gtest.h>

#include <cmath>
#include <fmt/format.h>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/rigid_supports.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

/// A box of 5 x 4 x 3 cells with a 2 x 2 x 3 plug cut free: two pieces.
TissueModel box_with_free_plug() {
  TissueModel model = test::make_box_model({5, 4, 3}, 2.0);
  const auto plug = [&](CellId c) {
    const Vec3i v = model.volume.cell_voxel(c);
    return v.x() >= 1 && v.x() <= 2 && v.y() >= 1 && v.y() <= 2;
  };
  model.volume.cut_links(test::faces_between(model.volume, plug));
  return model;
}

/// A smooth deformation plus, on `piece` only, a translation and an infinitesimal rotation.
Vector deformed_and_moved(const LinkedVolume& volume, const std::vector<int>& comp, int piece, double motion_scale) {
  Vector u(3 * static_cast<Eigen::Index>(volume.vertex_count()));
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const Vec3 x = volume.vertex_position_mm(v);
    u.segment<3>(3 * v) = Vec3(0.02 * x.x() * x.y(), 0.01 * std::sin(x.z()), 0.03 * x.x());
    if (comp[static_cast<std::size_t>(v)] == piece)
      u.segment<3>(3 * v) += motion_scale * (Vec3(0.4, -0.2, 0.7) + Vec3(0.01, 0.03, -0.02).cross(x));
  }
  return u;
}

/// Weighted mean translation and rotation moment of `piece` (zero after the removal).
Eigen::Matrix<double, 6, 1> rigid_moments(const LinkedVolume& volume, const std::vector<int>& comp, int piece,
                                          const Vector& weights, const Vector& u) {
  Eigen::Matrix<double, 6, 1> out = Eigen::Matrix<double, 6, 1>::Zero();
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    if (comp[static_cast<std::size_t>(v)] != piece) continue;
    const Vec3 x = volume.vertex_position_mm(v);
    const Vec3 wu = weights.segment<3>(3 * v).cwiseProduct(u.segment<3>(3 * v));
    out.head<3>() += wu;
    out.tail<3>() += x.cross(wu);
  }
  return out;
}

TEST(RigidMotion, ARigidMotionOfAListedPieceIsRemovedExactlyAndTheOtherPieceIsLeftAlone) {
  const TissueModel model = box_with_free_plug();
  const LinkedVolume& volume = model.volume;
  ASSERT_EQ(volume.component_count(), 2);
  const std::vector<int> comp = vertex_components(volume);
  const Vector mass = lumped_mass(model);
  const int plug = comp[0] == 0 ? 1 : 0;  // vertex 0 is a corner of the frame, not of the plug
  const std::vector<int> listed{plug};
  const RigidMotionRemover remover(volume, listed, mass);

  Vector still = deformed_and_moved(volume, comp, plug, 0.0);
  Vector moved = deformed_and_moved(volume, comp, plug, 1.0);
  remover.remove(still);
  remover.remove(moved);
  EXPECT_LT((moved - still).cwiseAbs().maxCoeff(), 1e-12);  // the added motion is gone, nothing else differs
  EXPECT_LT(rigid_moments(volume, comp, plug, mass, moved).cwiseAbs().maxCoeff(), 1e-12);

  // The frame's vertices are not touched.
  const Vector original = deformed_and_moved(volume, comp, plug, 1.0);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    if (comp[static_cast<std::size_t>(v)] == plug) continue;
    EXPECT_EQ(moved.segment<3>(3 * v), original.segment<3>(3 * v)) << v;
  }

  // A second removal finds nothing left to remove.
  Vector again = moved;
  remover.remove(again);
  EXPECT_LT((again - moved).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(RigidMotion, BadInputIsNamed) {
  const TissueModel model = box_with_free_plug();
  const Vector mass = lumped_mass(model);
  const std::vector<int> missing{2};
  try {
    RigidMotionRemover(model.volume, missing, mass);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "component 2 does not exist; expected 0 to 1");
  }
  const std::vector<int> first{0};
  try {
    RigidMotionRemover(model.volume, first, mass.head(6));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("rigid motion weights hold 6 values; expected one per dof ({})", mass.size()));
  }
  const RigidMotionRemover remover(model.volume, first, mass);
  Vector short_u = Vector::Zero(3);
  try {
    remover.remove(short_u);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("displacement holds 3 values; expected one per dof ({})", mass.size()));
  }
}

}  // namespace
}  // namespace cleave
