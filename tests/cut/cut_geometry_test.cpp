// Cut geometry on a plate: which links a round incision, a scalpel cut and a flap sever, where
// incisions are placed, and the exact refusals of bad requests (with the model left unchanged).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fmt/format.h>
#include <cmath>
#include <numbers>

#include "cleave/core/error.hpp"
#include "cleave/cut/cut_plan.hpp"
#include "cleave/cut/place_incisions.hpp"
#include "cut_test_models.hpp"

namespace cleave {
namespace {

using ::testing::HasSubstr;

constexpr double kH = 2.0;                // cell edge (mm)
const Vec3i kPlateCells{20, 20, 4};       // 40 x 40 x 8 mm, skin at z = 8

std::vector<int> component_sizes(const LinkedVolume& v) {
  std::vector<int> sizes(static_cast<std::size_t>(v.component_count()), 0);
  for (const int c : v.cell_components()) ++sizes[static_cast<std::size_t>(c)];
  std::sort(sizes.begin(), sizes.end());
  return sizes;
}

TEST(SegmentCrossesTriangle, HitsMissesAndParallel) {
  const Triangle t{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0)};
  EXPECT_TRUE(segment_crosses_triangle(Vec3(0.5, 0.5, -1), Vec3(0.5, 0.5, 1), t));
  EXPECT_FALSE(segment_crosses_triangle(Vec3(1.5, 1.5, -1), Vec3(1.5, 1.5, 1), t));  // beyond the hypotenuse
  EXPECT_FALSE(segment_crosses_triangle(Vec3(0.5, 0.5, 0.1), Vec3(0.5, 0.5, 1), t));  // stops short
  EXPECT_FALSE(segment_crosses_triangle(Vec3(-1, 0.5, 0), Vec3(1, 0.5, 0), t));      // in its plane
  EXPECT_TRUE(segment_crosses_triangle(Vec3(1, 1, -1), Vec3(1, 1, 1), t));           // on the edge
}

TEST(RoundIncision, CutsExactlyTheLinksCrossingTheWall) {
  TissueModel model = test::make_box(kPlateCells, kH);
  const BodySurface surface(model);
  const RoundIncision in{Vec3(20, 20, 8), 6.0, 4.0, PlugHandling::keep};
  const IncisionFrame frame = incision_frame(surface, in, 3.0);
  EXPECT_NEAR((frame.centre_mm - Vec3(20, 20, 8)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(frame.normal.dot(Vec3::UnitZ()), 1.0, 1e-9);
  const IncisionLinks l = round_incision_links(model.volume, frame, PlugHandling::keep);
  const LinkedVolume& v = model.volume;
  // Every link with one centre inside the radius and one outside, both above the depth, is cut; no other.
  int expected = 0;
  for (CellId c = 0; c < v.cell_count(); ++c)
    for (const Face f : {1, 3, 5}) {
      const CellId n = v.neighbor(c, f);
      if (n == kNone) continue;
      const Vec3 a = v.cell_center_mm(c), b = v.cell_center_mm(n);
      const bool across = (frame.radial_of(a) < 6.0) != (frame.radial_of(b) < 6.0);
      if (across && frame.depth_of(a) <= 4.0 && frame.depth_of(b) <= 4.0) ++expected;
    }
  EXPECT_EQ(static_cast<int>(l.links.size()), expected);
  EXPECT_GT(expected, 20);
  for (const CellFace& cf : l.links) {
    const Vec3 a = v.cell_center_mm(cf.cell), b = v.cell_center_mm(v.neighbor(cf.cell, cf.face));
    EXPECT_NE(frame.radial_of(a) < 6.0, frame.radial_of(b) < 6.0);
  }
  // The plug: cells within the radius in the two upper layers; it stays attached at its bottom.
  model.volume.cut_links(l.links);
  EXPECT_EQ(model.volume.component_count(), 1);
  const double plug_volume = std::numbers::pi * 36.0 * 4.0;
  EXPECT_NEAR(static_cast<double>(l.plug_cells.size()) * kH * kH * kH, plug_volume, 0.25 * plug_volume);
}

TEST(RoundIncision, RemovedPlugBecomesAFreePiece) {
  TissueModel model = test::make_box(kPlateCells, kH);
  const BodySurface surface(model);
  CutRequests r;
  r.incisions.push_back({Vec3(20, 20, 8), 6.0, 4.0, PlugHandling::remove});
  const CutPlan plan = plan_cuts(surface, r);
  apply_cut_plan(model.volume, plan);
  const std::vector<int> sizes = component_sizes(model.volume);
  ASSERT_EQ(sizes.size(), 2u);
  EXPECT_EQ(static_cast<std::size_t>(sizes[0]), plan.hidden_cells().size());
}

TEST(ScalpelCut, ThroughCutAcrossThePlateMakesTwoPieces) {
  TissueModel model = test::make_box(kPlateCells, kH);
  const BodySurface surface(model);
  CutRequests r;
  r.scalpel_cuts.push_back({{Vec3(20, 0.5, 8), Vec3(20, 39.5, 8)}, 8.0, 0.0});
  const CutPlan plan = plan_cuts(surface, r);
  EXPECT_NEAR(plan.scalpel_paths[0].length_mm, 39.0, 1e-6);
  apply_cut_plan(model.volume, plan);
  EXPECT_THAT(component_sizes(model.volume), ::testing::ElementsAre(10 * 20 * 4, 10 * 20 * 4));
  // Exactly the links across the plane x = 20 (between voxel columns 9 and 10) were cut.
  EXPECT_EQ(model.volume.cut_link_count(), 20 * 4);
}

TEST(ScalpelCut, HalfDepthCutKeepsOnePiece) {
  TissueModel model = test::make_box(kPlateCells, kH);
  const BodySurface surface(model);
  CutRequests r;
  r.scalpel_cuts.push_back({{Vec3(20, 0.5, 8), Vec3(20, 39.5, 8)}, 4.0, 0.0});
  apply_cut_plan(model.volume, plan_cuts(surface, r));
  EXPECT_EQ(model.volume.component_count(), 1);
  EXPECT_EQ(model.volume.cut_link_count(), 20 * 2);  // the two upper layers
}

TEST(Flap, UShapedFlapStaysOnItsHingeAndClosedFlapComesFree) {
  const std::vector<Vec3> path{Vec3(10, 10, 8), Vec3(10, 30, 8), Vec3(30, 30, 8), Vec3(30, 10, 8)};
  for (const FlapShape shape : {FlapShape::u_shaped, FlapShape::closed}) {
    TissueModel model = test::make_box(kPlateCells, kH);
    const BodySurface surface(model);
    CutRequests r;
    r.flaps.push_back({path, 4.0, shape});
    const CutPlan plan = plan_cuts(surface, r);
    EXPECT_EQ(plan.flaps[0].cells.size(), 10u * 10u * 2u);
    apply_cut_plan(model.volume, plan);
    if (shape == FlapShape::u_shaped)
      EXPECT_EQ(model.volume.component_count(), 1);
    else
      EXPECT_THAT(component_sizes(model.volume), ::testing::ElementsAre(200, 20 * 20 * 4 - 200));
  }
}

TEST(PlaceIncisions, PoissonDiskSpacingRegionAndCount) {
  const TissueModel model = test::make_box({30, 30, 4}, kH);
  const BodySurface surface(model);
  IncisionPattern p;
  p.radius_mm = 3;
  p.depth_mm = 3;
  p.spacing_mm = 10;
  p.region = IncisionRegion::box(Vec3(0, 0, 7.5), Vec3(60, 60, 9));
  const std::vector<RoundIncision> all = place_incisions(surface, p);
  // A maximal 10 mm Poisson-disk set on the usable 48 x 48 mm top (rims stay on the plate) holds
  // between (48/20)^2 ... the hexagonal packing (about 2 (48/10)^2 / sqrt 3 + boundary) points.
  EXPECT_GE(all.size(), 12u);
  EXPECT_LE(all.size(), 40u);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_NEAR(all[i].centre_mm.z(), 8.0, 1e-9);
    for (std::size_t j = i + 1; j < all.size(); ++j) EXPECT_GE((all[i].centre_mm - all[j].centre_mm).norm(), 10.0);
  }
  p.count = 5;
  EXPECT_EQ(place_incisions(surface, p).size(), 5u);
  EXPECT_EQ(place_incisions(surface, p)[3].centre_mm, place_incisions(surface, p)[3].centre_mm);  // seeded
  p.count = 1000;
  try {
    place_incisions(surface, p);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("1000 incisions asked for, but only {} fit at spacing 10 mm; "
                                                 "expected at most {} or a smaller spacing",
                                                 all.size(), all.size()));
  }
  p.count.reset();
  p.spacing_mm = 6.5;
  EXPECT_THROW(
      {
        try {
          place_incisions(surface, p);
        } catch (const InputError& e) {
          EXPECT_STREQ(e.what(), "incision spacing 6.5 mm; expected at least the diameter plus one cell (8 mm) so "
                                 "that incisions stay apart");
          throw;
        }
      },
      InputError);
}

/// Plans `r` on a fresh plate and returns the error message ("" when accepted); checks that the
/// model is unchanged either way (plan_cuts never cuts).
std::string refusal(const CutRequests& r) {
  const TissueModel model = test::make_box(kPlateCells, kH);
  const BodySurface surface(model);
  const VertexId vertices = model.volume.vertex_count();
  std::string message;
  try {
    plan_cuts(surface, r);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(model.volume.cut_link_count(), 0);
  EXPECT_EQ(model.volume.vertex_count(), vertices);
  return message;
}

TEST(CutValidation, BadRequestsAreRefusedWithClearMessages) {
  CutRequests big;
  big.incisions.push_back({Vec3(20, 20, 8), 30.0, 2.0, PlugHandling::keep});
  EXPECT_EQ(refusal(big), "incision 0: radius 30 mm makes the incision larger than the body (40 mm across); expected "
                          "a diameter below that");

  CutRequests off;
  off.incisions.push_back({Vec3(20, 20, 20), 4.0, 2.0, PlugHandling::keep});
  EXPECT_EQ(refusal(off), "incision 0: incision centre (20, 20, 20) mm is 12 mm off the body's surface; expected a "
                          "point within 3 mm of it");

  CutRequests edge;
  edge.incisions.push_back({Vec3(2, 20, 8), 6.0, 2.0, PlugHandling::keep});
  EXPECT_THAT(refusal(edge), HasSubstr("reaches off the body's surface; expected an incision that fits on the body"));

  CutRequests deep;
  deep.incisions.push_back({Vec3(20, 20, 8), 4.0, 12.0, PlugHandling::keep});
  EXPECT_EQ(refusal(deep), "incision 0: depth 12 mm is beyond the body's thickness there (8 mm); expected at most 8 mm");

  CutRequests zero;
  zero.scalpel_cuts.push_back({{Vec3(20, 20, 8), Vec3(20, 20, 8)}, 2.0, 0.0});
  EXPECT_EQ(refusal(zero), "cut 0: path is 0 mm long; expected at least half a cell (1 mm)");

  CutRequests one_point;
  one_point.scalpel_cuts.push_back({{Vec3(20, 20, 8)}, 2.0, 0.0});
  EXPECT_EQ(refusal(one_point), "cut 0: path has 1 point(s); expected at least 2");

  CutRequests off_path;
  off_path.scalpel_cuts.push_back({{Vec3(10, 20, 8), Vec3(30, 20, 30)}, 2.0, 0.0});
  EXPECT_EQ(refusal(off_path), "cut 0: path point 1 (30, 20, 30) mm is 22 mm off the body's surface; expected a "
                               "point within 3 mm of it");

  CutRequests through;
  through.scalpel_cuts.push_back({{Vec3(10, 20, 8), Vec3(30, 20, 8)}, 9.5, 0.0});
  EXPECT_THAT(refusal(through), HasSubstr("cut 0: depth 9.5 mm is beyond the body's thickness there"));

  CutRequests bowtie;
  bowtie.flaps.push_back(
      {{Vec3(10, 10, 8), Vec3(30, 30, 8), Vec3(30, 10, 8), Vec3(10, 30, 8)}, 2.0, FlapShape::closed});
  EXPECT_EQ(refusal(bowtie), "flap 0: flap path intersects itself (segment 0 crosses segment 2); expected a simple "
                             "closed or U-shaped path");

  // One good request and one bad one: nothing at all is cut.
  CutRequests mixed;
  mixed.incisions.push_back({Vec3(20, 20, 8), 4.0, 2.0, PlugHandling::keep});
  mixed.scalpel_cuts.push_back({{Vec3(20, 20, 8), Vec3(20, 20, 8)}, 2.0, 0.0});
  EXPECT_THAT(refusal(mixed), HasSubstr("cut 0: path is 0 mm long"));
}

}  // namespace
}  // namespace cleave
