// Strokes to eigenvector frames: tube stroke directions, direction (sign) invariance, no dead zone
// between antiparallel strokes, crossing strokes stay smooth, frames orthonormal.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <limits>
#include <string>

#include "cleave/core/error.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cstdlib>
#include <vector>

#include "cleave/stress/direction_frames.hpp"
#include "cleave/stress/line_field_interpolation.hpp"
#include "cleave/stress/stroke_constraints.hpp"
#include "cleave/stress/surface_cells.hpp"
#include "stress_test_models.hpp"

namespace cleave {
namespace {

struct Field {
  std::vector<Mat3> langer_tensors;
  std::vector<DirectionFrame> frames;
};

Field directions(const TissueModel& m, const std::vector<DesignStroke>& strokes) {
  const DesignWeights w;
  const double tol = 2.0 * m.volume.grid().cell_size_mm;
  LineFieldInterpolator langer(m.volume, w);
  LineFieldInterpolator normal(m.volume, w);
  Field f;
  f.langer_tensors = langer.interpolate(stroke_line_targets(m, strokes, tol));
  f.frames = direction_frames(f.langer_tensors, normal.interpolate(surface_normal_targets(m)));
  return f;
}

TEST(DirectionField, CircumferentialStrokeGivesCircumferentialLangerEverywhere) {
  const TissueModel m = test::builtin_model("cylinder");
  const double z_mid = m.volume.grid().origin_mm.z() + 0.5 * m.volume.grid().extent_mm().z();
  const Field f = directions(m, {test::circumferential_stroke(m, z_mid)});
  double worst = 0;
  for (CellId c = 0; c < m.volume.cell_count(); ++c)
    worst = std::max(worst, angle_between_lines_deg(f.frames[static_cast<std::size_t>(c)].langer,
                                           test::circumferential(m, m.volume.cell_center_mm(c))));
  EXPECT_LT(worst, 5.0);
}

TEST(DirectionField, AxialStrokeGivesAxialLangerEverywhere) {
  const TissueModel m = test::builtin_model("cylinder");
  const GridSpec& g = m.volume.grid();
  const double z0 = g.origin_mm.z() + 0.25 * g.extent_mm().z();
  const double z1 = g.origin_mm.z() + 0.75 * g.extent_mm().z();
  const Field f = directions(m, {test::axial_stroke(m, 0.3, z0, z1)});
  double worst = 0;
  // The tube's end caps have an axial surface normal, so their Langer direction cannot be axial:
  // the claim holds away from the caps (two cell layers at each end are left out).
  const int nz = g.dims.z();
  for (CellId c = 0; c < m.volume.cell_count(); ++c)
    if (const int z = m.volume.cell_voxel(c).z(); z >= 2 && z < nz - 2)
      worst = std::max(worst, angle_between_lines_deg(f.frames[static_cast<std::size_t>(c)].langer, Vec3::UnitZ()));
  EXPECT_LT(worst, 5.0);
}

TEST(DirectionField, FramesAreOrthonormalAndRightHanded) {
  const TissueModel m = test::builtin_model("cylinder");
  const double z_mid = m.volume.grid().origin_mm.z() + 0.5 * m.volume.grid().extent_mm().z();
  const Field f = directions(m, {test::circumferential_stroke(m, z_mid)});
  for (const DirectionFrame& fr : f.frames) {
    Mat3 q;
    q << fr.langer, fr.cross, fr.normal;
    ASSERT_LT((q.transpose() * q - Mat3::Identity()).norm(), 1e-12);
    ASSERT_NEAR(q.determinant(), 1.0, 1e-12);
  }
}

TEST(DirectionField, FramesFromKeptNormalAxesEqualFramesFromTheNormalTensors) {
  // The designer keeps normal_axes(normal tensors) and rebuilds only the Langer part after a
  // stroke edit: the frames must be the very same, also where a tensor carries no direction.
  const TissueModel m = test::builtin_model("cylinder");
  const double z_mid = m.volume.grid().origin_mm.z() + 0.5 * m.volume.grid().extent_mm().z();
  const DesignWeights w;
  LineFieldInterpolator langer(m.volume, w);
  LineFieldInterpolator normal(m.volume, w);
  std::vector<Mat3> langer_tensors =
      langer.interpolate(stroke_line_targets(m, {test::circumferential_stroke(m, z_mid)}, 2.0 * m.volume.grid().cell_size_mm));
  std::vector<Mat3> normal_tensors = normal.interpolate(surface_normal_targets(m));
  normal_tensors[0] = Mat3::Zero();  // no normal: the Langer tensor's weakest axis
  normal_tensors[1] = Mat3::Zero();
  langer_tensors[1] = Mat3::Zero();  // neither: the fixed axes
  const std::vector<Vec3> axes = normal_axes(normal_tensors);
  EXPECT_EQ(axes[0], Vec3::Zero());
  const std::vector<DirectionFrame> from_tensors = direction_frames(langer_tensors, normal_tensors);
  const std::vector<DirectionFrame> from_axes = direction_frames(langer_tensors, axes);
  ASSERT_EQ(from_axes.size(), from_tensors.size());
  for (std::size_t c = 0; c < from_axes.size(); ++c) {
    ASSERT_EQ(from_axes[c].langer, from_tensors[c].langer) << "cell " << c;
    ASSERT_EQ(from_axes[c].cross, from_tensors[c].cross) << "cell " << c;
    ASSERT_EQ(from_axes[c].normal, from_tensors[c].normal) << "cell " << c;
  }
  EXPECT_EQ(from_axes[1].normal, Vec3::UnitZ());
  std::string message;
  try {
    direction_frames(langer_tensors, std::vector<Vec3>(3));
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, fmt::format("direction frames got {} Langer tensors and 3 normal axes; expected one of each per cell",
                                 langer_tensors.size()));
}

TEST(DirectionField, TheLangerAxisIsThePrincipalAxisOfTheTensorProjectedNormalToTheNormal) {
  // The frames solve a 2x2 problem in the plane normal to n; the reference here is the 3x3
  // eigen-solve (iterative) of P L P, P = I - n n^T, on random tensors and normals, the axis
  // compared up to its sign. Where the projected tensor has no preferred axis (equal in-plane
  // eigenvalues, or none above 1e-12) the axis is any unit vector normal to n.
  std::srand(7);
  std::vector<Mat3> langer_tensors;
  std::vector<Vec3> normals;
  for (int i = 0; i < 2000; ++i) {
    const Mat3 a = Mat3::Random();
    langer_tensors.push_back(a * a.transpose());  // positive semidefinite, as interpolated line tensors
    normals.push_back(Vec3::Random().normalized());
  }
  const Vec3 n0 = Vec3::UnitZ();
  langer_tensors.push_back(Mat3::Identity());  // isotropic in the plane
  normals.push_back(n0);
  langer_tensors.push_back(Mat3::Zero());  // no direction
  normals.push_back(n0);
  langer_tensors.push_back(Vec3::UnitX() * Vec3::UnitX().transpose());  // along a basis axis of the plane
  normals.push_back(n0);
  langer_tensors.push_back(Vec3::UnitY() * Vec3::UnitY().transpose());
  normals.push_back(n0);
  const std::vector<DirectionFrame> frames = direction_frames(langer_tensors, normals);
  int compared = 0;
  for (std::size_t c = 0; c < frames.size(); ++c) {
    const DirectionFrame& f = frames[c];
    EXPECT_NEAR(f.langer.norm(), 1.0, 1e-12) << "cell " << c;
    EXPECT_NEAR(f.langer.dot(normals[c]), 0.0, 1e-12) << "cell " << c;
    EXPECT_NEAR((f.normal.cross(f.langer) - f.cross).norm(), 0.0, 1e-12) << "cell " << c;
    const Mat3 p = Mat3::Identity() - normals[c] * normals[c].transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> reference(p * langer_tensors[c] * p);
    const Vec3 values = reference.eigenvalues();
    if (values[2] - values[1] < 1e-6 * std::max(values[2], 1.0)) continue;  // no preferred axis
    EXPECT_NEAR(std::abs(f.langer.dot(reference.eigenvectors().col(2))), 1.0, 1e-10) << "cell " << c;
    ++compared;
  }
  EXPECT_GE(compared, 2000);
  EXPECT_NEAR(std::abs(frames[2002].langer.x()), 1.0, 1e-15);
  EXPECT_NEAR(std::abs(frames[2003].langer.y()), 1.0, 1e-15);
}

TEST(DirectionField, ReversingAnySubsetOfStrokesGivesTheSameField) {
  const TissueModel m = test::builtin_model("cylinder");
  const GridSpec& g = m.volume.grid();
  const double z_mid = g.origin_mm.z() + 0.5 * g.extent_mm().z();
  std::vector<DesignStroke> strokes = {test::circumferential_stroke(m, z_mid),
                                       test::axial_stroke(m, 1.0, g.origin_mm.z() + 10.0, g.origin_mm.z() + 40.0),
                                       test::axial_stroke(m, 3.5, g.origin_mm.z() + 20.0, g.origin_mm.z() + 90.0)};
  const Field reference = directions(m, strokes);
  for (int subset = 1; subset < 8; ++subset) {
    std::vector<DesignStroke> flipped = strokes;
    for (int s = 0; s < 3; ++s)
      if ((subset >> s) & 1) std::reverse(flipped[static_cast<std::size_t>(s)].points_mm.begin(), flipped[static_cast<std::size_t>(s)].points_mm.end());
    const Field f = directions(m, flipped);
    double worst = 0;
    for (std::size_t c = 0; c < f.frames.size(); ++c)
      worst = std::max(worst, (f.langer_tensors[c] - reference.langer_tensors[c]).cwiseAbs().maxCoeff());
    EXPECT_LT(worst, 1e-12) << "subset " << subset;
  }
}

TEST(DirectionField, AntiparallelStrokesSideBySideLeaveNoDeadZone) {
  const TissueModel m = test::builtin_model("plate");  // 100 x 100 x 10 mm, 2.5 mm cells
  const GridSpec& g = m.volume.grid();
  const double top = g.origin_mm.z() + g.extent_mm().z();
  DesignStroke a{{{20, 40, top}, {80, 40, top}}, StrokePlacement::surface};
  DesignStroke b{{{80, 60, top}, {20, 60, top}}, StrokePlacement::surface};  // drawn the other way
  const Field f = directions(m, {a, b});
  // Between the strokes the Langer line tensor keeps its strength and its direction x.
  double weakest = 1.0, worst_angle = 0.0;
  for (CellId c = 0; c < m.volume.cell_count(); ++c) {
    const Vec3 p = m.volume.cell_center_mm(c);
    if (p.x() < 30 || p.x() > 70 || p.y() < 40 || p.y() > 60) continue;
    const Mat3& t = f.langer_tensors[static_cast<std::size_t>(c)];
    weakest = std::min(weakest, t(0, 0));
    worst_angle = std::max(worst_angle, angle_between_lines_deg(f.frames[static_cast<std::size_t>(c)].langer, Vec3::UnitX()));
  }
  EXPECT_GT(weakest, 0.9);
  EXPECT_LT(worst_angle, 1.0);
}

TEST(DirectionField, StrokesCrossingAtRightAnglesGiveASmoothFieldWithoutNaN) {
  const TissueModel m = test::builtin_model("plate");
  const double top = m.volume.grid().origin_mm.z() + m.volume.grid().extent_mm().z();
  DesignStroke a{{{10, 50, top}, {90, 50, top}}, StrokePlacement::surface};
  DesignStroke b{{{50, 10, top}, {50, 90, top}}, StrokePlacement::surface};
  const Field f = directions(m, {a, b});
  std::vector<bool> on_stroke(static_cast<std::size_t>(m.volume.cell_count()), false);
  for (const LineTarget& t : stroke_line_targets(m, {a, b}, 5.0)) on_stroke[static_cast<std::size_t>(t.cell)] = true;
  double jump = 0;
  for (CellId c = 0; c < m.volume.cell_count(); ++c) {
    const DirectionFrame& fr = f.frames[static_cast<std::size_t>(c)];
    ASSERT_TRUE(fr.langer.allFinite() && fr.cross.allFinite() && fr.normal.allFinite());
    ASSERT_TRUE(f.langer_tensors[static_cast<std::size_t>(c)].allFinite());
    for (Face face = 0; face < kFaceCount; ++face)
      if (m.volume.linked(c, face) && !on_stroke[static_cast<std::size_t>(c)] &&
          !on_stroke[static_cast<std::size_t>(m.volume.neighbor(c, face))])
        jump = std::max(jump, (f.langer_tensors[static_cast<std::size_t>(c)] -
                               f.langer_tensors[static_cast<std::size_t>(m.volume.neighbor(c, face))]).norm());
  }
  // Continuity off the strokes: neighbouring line tensors differ by about a third of the jump
  // between the two stroke directions at most (|x x^T - y y^T| = sqrt 2); on the strokes they are the targets.
  EXPECT_LT(jump, 0.5);
}

TEST(DirectionField, InteriorStrokeConstrainsCellsInsideAndRefusesPointsOutside) {
  const TissueModel m = test::builtin_model("plate");
  DesignStroke inside{{{20, 50, 5}, {80, 50, 5}}, StrokePlacement::interior};
  const auto targets = stroke_line_targets(m, {inside}, 5.0);
  ASSERT_FALSE(targets.empty());
  for (const LineTarget& t : targets) {
    EXPECT_EQ(m.volume.cell_voxel(t.cell).z(), 2);  // z = 5 mm with 2.5 mm cells: not snapped to the surface
    EXPECT_NEAR(t.tensor(0, 0), 1.0, 1e-12);
  }
  DesignStroke outside{{{20, 50, 5}, {80, 50, 30}}, StrokePlacement::interior};
  EXPECT_THROW(
      {
        try {
          stroke_line_targets(m, {inside, outside}, 5.0);
        } catch (const InputError& e) {
          EXPECT_STREQ(e.what(), "design stroke 1 point 1 at (80, 50, 30) mm is outside the body; expected an interior stroke inside it");
          throw;
        }
      },
      InputError);
}

TEST(DirectionField, BadStrokesAreRefusedWithTheirIndex) {
  const TissueModel m = test::builtin_model("plate");
  const auto message = [&](const DesignStroke& s) {
    try {
      stroke_line_targets(m, {s}, 5.0);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(DesignStroke{{}, StrokePlacement::surface}), "design stroke 0 has 0 points; expected at least two points");
  EXPECT_EQ(message(DesignStroke{{{1, 2, 10}}, StrokePlacement::surface}), "design stroke 0 has 1 point; expected at least two points");
  EXPECT_EQ(message(DesignStroke{{{1, 2, 10}, {std::numeric_limits<double>::quiet_NaN(), 2, 10}}, StrokePlacement::surface}),
            "design stroke 0 point 1 is not finite; expected coordinates in mm");
  EXPECT_EQ(message(DesignStroke{{{1, 2, 10}, {std::numeric_limits<double>::infinity(), 2, 10}}, StrokePlacement::surface}),
            "design stroke 0 point 1 is not finite; expected coordinates in mm");
  EXPECT_EQ(message(DesignStroke{{{50, 50, 10}, {60, 50, 30}}, StrokePlacement::surface}),
            "design stroke 0 point 1 at (60, 50, 30) mm is 20.1 mm from the body surface; expected within 5 mm");
}

}  // namespace
}  // namespace cleave
