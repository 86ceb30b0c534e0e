// What the released stress does to cuts, against the paper's results (docs/VALIDATION.md):
//   fig. 8   a cut across Langer's lines gapes wider than an equal cut along them;
//   fig. 10  round incisions stay round under isotropic tension and become ellipses along the
//            Langer direction under anisotropic tension;
//   and the invariants: cutting nothing changes nothing; two free pieces stay finite and in place.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include "cleave/cut/cut_plan.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/solve_static.hpp"
#include "cleave/cut/body_surface.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "cleave/viz/incision_ellipses.hpp"
#include "cleave/viz/wound_measures.hpp"
#include "cut_test_models.hpp"

namespace cleave {
namespace {

constexpr double kLangerKPa = 20.0;  // paper section 7: tension along Langer's lines
constexpr double kCrossKPa = 10.0;   // and across them
constexpr double kYoungKPa = 80.0;
constexpr double kPoisson = 0.4;

/// By default the multigrid-preconditioned CG solver (relative residual 1e-8): the same openings
/// as CHOLMOD to the digits reported here, several times faster on these models.
StaticOptions held(const LinkedVolume& volume, std::vector<VertexId> fixed, SolverKind solver = SolverKind::multigrid_cg) {
  StaticOptions o;
  o.solver = solver;
  o.fixed_vertices = std::move(fixed);
  (void)volume;
  return o;
}

/// Vertices on the lateral rim of a plate [0, w] x [0, w] (x or y at an edge).
std::vector<VertexId> plate_rim(const LinkedVolume& v, double w) {
  std::vector<VertexId> out;
  for (VertexId i = 0; i < v.vertex_count(); ++i) {
    const Vec3 p = v.vertex_position_mm(i);
    if (p.x() <= 0 || p.y() <= 0 || p.x() >= w || p.y() >= w) out.push_back(i);
  }
  return out;
}

/// Plate 100 x 100 x 10 mm (2.5 mm cells), rim held, 20 kPa along x (Langer), 10 kPa along y.
struct Plate {
  TissueModel model = test::make_box({40, 40, 4}, 2.5, kYoungKPa, kPoisson);
  std::vector<Vec6> stress = test::uniform_stress(model, test::biaxial(Vec3::UnitX(), kLangerKPa, Vec3::UnitY(), kCrossKPa));
};

double wound_width_after(const std::vector<Vec3>& path, double depth_mm) {
  Plate p;
  const BodySurface surface(p.model);
  CutRequests r;
  r.scalpel_cuts.push_back({path, depth_mm, 0.0});
  const CutPlan plan = plan_cuts(surface, r);
  apply_cut_plan(p.model.volume, plan);
  const StaticResult s = solve_static(p.model, p.stress, held(p.model.volume, plate_rim(p.model.volume, 100.0)));
  const WoundWidth w = scalpel_wound_width(p.model.volume, s.displacement_mm, plan.scalpel_paths[0]);
  return w.max_mm;
}

TEST(ReleasePhysics, CuttingNothingChangesNothing) {
  Plate p;
  const BodySurface surface(p.model);
  const CutPlan plan = plan_cuts(surface, CutRequests{});
  EXPECT_EQ(apply_cut_plan(p.model.volume, plan).links_cut, 0);
  const StaticResult s = solve_static(p.model, p.stress, held(p.model.volume, plate_rim(p.model.volume, 100.0)));
  double max_u = 0;
  for (const Vec3& u : s.displacement_mm) max_u = std::max(max_u, u.norm());
  EXPECT_LT(max_u, 1e-9);  // a uniform tangential stress held at the rim is in equilibrium
}

TEST(ReleasePhysics, Fig8CutAcrossLangerLinesGapesWiderThanAlong) {
  // 40 mm cuts through half the thickness at the plate's centre; Langer's lines run along x.
  const double across = wound_width_after({Vec3(50, 30, 10), Vec3(50, 70, 10)}, 5.0);  // path along y
  const double along = wound_width_after({Vec3(30, 50, 10), Vec3(70, 50, 10)}, 5.0);   // path along x
  RecordProperty("across_max_width_mm", std::to_string(across));
  RecordProperty("along_max_width_mm", std::to_string(along));
  std::printf("fig8: across %.4f mm, along %.4f mm, ratio %.3f\n", across, along, across / along);
  EXPECT_GT(along, 0.0);
  EXPECT_GE(across, 1.5 * along);
}


/// Displacement of the cut volume relative to the uncut solution: each (cell, corner) vertex of
/// `cut` minus the uncut vertex at the same (cell, corner). Removes the settling of a direct
/// stress field that is not exactly self-balanced, leaving what the cuts released.
std::vector<Vec3> released_by_cuts(const LinkedVolume& cut, std::span<const Vec3> u_cut, const LinkedVolume& uncut,
                                   std::span<const Vec3> u_uncut) {
  std::vector<Vec3> out(u_cut.begin(), u_cut.end());
  for (CellId c = 0; c < cut.cell_count(); ++c)
    for (int k = 0; k < kCornerCount; ++k)
      out[static_cast<std::size_t>(cut.corner_vertex(c, k))] =
          u_cut[static_cast<std::size_t>(cut.corner_vertex(c, k))] - u_uncut[static_cast<std::size_t>(uncut.corner_vertex(c, k))];
  return out;
}

TEST(ReleasePhysics, Fig10TubeIncisionsRoundAboveEllipticalBelow) {
  // The paper's tube (outer diameter 84 mm) at 2.625 mm cells. Langer direction: the tube's axis.
  // Upper half: 20 kPa along the axis and around it (isotropic); lower half: around it halved.
  ShapeResolution res;
  res.cells = Vec3i(32, 32, 40);
  Material m;
  m.youngs_modulus_kPa = kYoungKPa;
  m.poisson_ratio = kPoisson;
  TissueModel model = make_tissue_model("cylinder", make_builtin_shape("cylinder", res), {{Label{1}, m}});
  const double length = model.volume.grid().extent_mm().z();
  const Vec3 axis_point(42, 42, 0);
  std::vector<Vec6> stress;
  for (CellId c = 0; c < model.volume.cell_count(); ++c) {
    const Vec3 p = model.volume.cell_center_mm(c);
    const Vec3 around = Vec3(-(p.y() - axis_point.y()), p.x() - axis_point.x(), 0).normalized();
    const double cross = p.z() > 0.5 * length ? kLangerKPa : 0.5 * kLangerKPa;
    stress.push_back(test::biaxial(Vec3::UnitZ(), kLangerKPa, around, cross));
  }
  // Held: both ends and the inner wall (the tube sits on a rigid core, like skin on the body), so
  // that the tangential tension cannot relax before the incisions are made.
  constexpr double kInnerWallMm = 0.615 * 42.0 + 1.0;
  std::vector<VertexId> ends;
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v) {
    const Vec3 p = model.volume.vertex_position_mm(v);
    if (p.z() <= 0 || p.z() >= length || std::hypot(p.x() - axis_point.x(), p.y() - axis_point.y()) <= kInnerWallMm)
      ends.push_back(v);
  }
  // The multigrid CG: its single-precision V-cycle stalled on this tube (relative residual 0.0175
  // after 65 iterations) until CG fell back to the double cycle after 40 float iterations (4b9fdf6).
  constexpr SolverKind kTubeSolver = SolverKind::multigrid_cg;
  const LinkedVolume uncut = model.volume;
  const StaticResult before = solve_static(model, stress, held(model.volume, ends, kTubeSolver));

  constexpr int kAround = 6;
  constexpr double kRadiusMm = 7.0, kDepthMm = 6.0;
  CutRequests r;
  for (const double z : {0.75 * length, 0.25 * length})
    for (int k = 0; k < kAround; ++k) {
      const double t = 2 * std::numbers::pi * (k + 0.5) / kAround;
      r.incisions.push_back({Vec3(42 + 42 * std::cos(t), 42 + 42 * std::sin(t), z), kRadiusMm, kDepthMm, PlugHandling::remove});
    }
  const BodySurface surface(model);
  const CutPlan plan = plan_cuts(surface, r);
  apply_cut_plan(model.volume, plan);
  const StaticResult after = solve_static(model, stress, held(model.volume, ends, kTubeSolver));
  const std::vector<Vec3> u = released_by_cuts(model.volume, after.displacement_mm, uncut, before.displacement_mm);
  for (std::size_t i = 0; i < plan.incisions.size(); ++i) {
    const bool upper = i < kAround;
    const auto mi = measure_incision(surface, u, plan.incisions[i], TangentDirection{Vec3::UnitZ(), upper ? 1.0 : 2.0});
    ASSERT_TRUE(mi) << "incision " << i;
    std::printf("fig10 %s %zu: outer %.3f x %.3f ratio %.4f angle %.2f deg, inner ratio %.4f gap %.3f opening %.3f\n",
                upper ? "upper" : "lower", i, mi->outer.semi_major, mi->outer.semi_minor, mi->outer.axis_ratio(),
                *mi->langer_angle_deg, mi->inner.axis_ratio(), mi->gap_mm, mi->opening_mm);
    EXPECT_GT(mi->opening_mm, 0.0);
    if (upper) {
      EXPECT_LT(mi->outer.axis_ratio(), 1.05) << "incision " << i;
    } else {
      EXPECT_GT(mi->outer.axis_ratio(), 1.15) << "incision " << i;
      EXPECT_LT(*mi->langer_angle_deg, 10.0) << "incision " << i;
    }
  }
}

TEST(ReleasePhysics, TwoFreePiecesStayFiniteAndInPlace) {
  // A free plate (nothing held) with a tangential stress, cut through into two halves.
  Plate p;
  const BodySurface surface(p.model);
  CutRequests r;
  r.scalpel_cuts.push_back({{Vec3(50, 0.5, 10), Vec3(50, 99.5, 10)}, 10.0, 0.0});
  apply_cut_plan(p.model.volume, plan_cuts(surface, r));
  ASSERT_EQ(p.model.volume.component_count(), 2);
  const StaticResult s = solve_static(p.model, p.stress, held(p.model.volume, {}));
  EXPECT_EQ(s.free_components, 2);
  std::vector<Vec3> mean(2, Vec3::Zero());
  std::vector<int> count(2, 0);
  double max_u = 0;
  for (CellId c = 0; c < p.model.volume.cell_count(); ++c) {
    const int comp = p.model.volume.cell_components()[static_cast<std::size_t>(c)];
    for (int k = 0; k < kCornerCount; ++k) {
      const Vec3& u = s.displacement_mm[static_cast<std::size_t>(p.model.volume.corner_vertex(c, k))];
      ASSERT_TRUE(u.allFinite());
      max_u = std::max(max_u, u.norm());
      mean[static_cast<std::size_t>(comp)] += u;
      ++count[static_cast<std::size_t>(comp)];
    }
  }
  // Each half shrinks by about sigma / E of its size (20/80 * 50 mm = 12.5 mm at most) and does not drift.
  EXPECT_LT(max_u, 0.25 * 100.0);
  for (int k = 0; k < 2; ++k) EXPECT_LT((mean[static_cast<std::size_t>(k)] / count[static_cast<std::size_t>(k)]).norm(), 0.05);
}


TEST(ReleasePhysics, Section7AbdomenFiveCentimetreCutAcrossTheLinesOpensFiveToTwentyMm) {
  // The built-in abdominal wall (10.8 mm thick), E = 80 kPa, nu = 0.4; Langer's lines
  // run horizontally around the body (x projected into the tangent plane) with 20 kPa, 10 kPa
  // across; the wall's rim is held. A 5 cm cut across the lines through the wall (10 mm), on the dome's flank.
  Material m;
  m.youngs_modulus_kPa = kYoungKPa;
  m.poisson_ratio = kPoisson;
  // 3.6 mm cells (3 through the wall): at the default 5 mm the two-cell-thick wall is too stiff in
  // shear and the opening is underestimated (4.98 mm measured there; 6.79 mm at 3.6 mm, 7.66 mm at 2.5 mm).
  ShapeResolution res;
  res.cell_size_mm = 3.6;
  TissueModel model = make_tissue_model("abdomen", make_builtin_shape("abdomen", res), {{1, m}, {2, m}, {3, m}});
  const BodySurface surface(model);
  std::vector<Vec6> stress;
  for (CellId c = 0; c < model.volume.cell_count(); ++c) {
    const Vec3 n = surface.normal_at(model.volume.cell_center_mm(c));
    const Vec3 langer = (Vec3::UnitX() - Vec3::UnitX().dot(n) * n).normalized();
    stress.push_back(test::biaxial(langer, kLangerKPa, n.cross(langer).normalized(), kCrossKPa));
  }
  const Vec3 extent = model.volume.grid().extent_mm();
  constexpr double kRimMm = 5.0;
  std::vector<VertexId> rim;
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v) {
    const Vec3 p = model.volume.vertex_position_mm(v);
    if (p.x() <= kRimMm || p.z() <= kRimMm || p.x() >= extent.x() - kRimMm || p.z() >= extent.z() - kRimMm) rim.push_back(v);
  }
  // The wall lies on the body beneath: the free faces of the innermost layer (muscle, label 3)
  // are held, so that the tangential tension cannot relax by the dome sagging before the cut.
  constexpr Label kMuscle = 3;
  for (CellId c = 0; c < model.volume.cell_count(); ++c)
    if (model.volume.cell_label(c) == kMuscle)
      for (Face f = 0; f < kFaceCount; ++f)
        if (model.volume.neighbor(c, f) == kNone)
          for (const int k : face_corners(f)) rim.push_back(model.volume.corner_vertex(c, k));
  std::sort(rim.begin(), rim.end());
  rim.erase(std::unique(rim.begin(), rim.end()), rim.end());
  const auto skin = [&](double x, double z) {
    double y = extent.y();
    while (y > 0 && !surface.inside(Vec3(x, y, z))) y -= 0.25;
    return Vec3(x, y, z);
  };
  constexpr double kCutDepthMm = 10.0;
  const double x = 0.32 * extent.x(), zc = 0.5 * extent.z();
  CutRequests r;
  r.scalpel_cuts.push_back({{skin(x, zc - 25), skin(x, zc + 25)}, kCutDepthMm, 0.0});
  const CutPlan plan = plan_cuts(surface, r);
  EXPECT_NEAR(plan.scalpel_paths[0].length_mm, 50.0, 2.5);
  apply_cut_plan(model.volume, plan);
  const StaticResult s = solve_static(model, stress, held(model.volume, rim));
  const WoundWidth w = scalpel_wound_width(model.volume, s.displacement_mm, plan.scalpel_paths[0]);
  double max_u = 0;
  for (const Vec3& u : s.displacement_mm) max_u = std::max(max_u, u.norm());
  std::printf("section7: 5 cm cut across the lines opens %.3f mm at most, %.3f mm on average (%zu links cut, %d samples, max |u| %.3f mm, skin y %.2f)\n",
              w.max_mm, w.mean_mm, plan.steps[0].links.size(), w.samples, max_u, plan.scalpel_paths[0].skin_mm[10].y());
  RecordProperty("max_width_mm", std::to_string(w.max_mm));
  EXPECT_GE(w.max_mm, 5.0);
  EXPECT_LE(w.max_mm, 20.0);
}

}  // namespace
}  // namespace cleave
