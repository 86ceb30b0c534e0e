// The render surface: closed and oriented, genus, enclosed volume, cuts open it, embedding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "cleave/core/error.hpp"
#include "cleave/surface/render_surface.hpp"
#include "cleave/surface/surface_measures.hpp"
#include "cleave/surface/surface_topology.hpp"
#include "surface_test_models.hpp"

namespace cleave {
namespace {

using test::builtin_model;
using test::links_across_x;
using test::mask_model;

SurfaceTopology topology_of(const RenderSurface& s) { return surface_topology(s.triangles, s.vertex_count()); }

TEST(RenderSurface, PlateIsClosedGenusZeroAndEnclosesExactlyItsVolume) {
  const TissueModel model = builtin_model("plate");
  const RenderSurface s = build_render_surface(model);
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.euler_characteristic(), 2);
  // 40x40x4 cells: one quad per boundary face, two triangles per quad, one vertex per boundary corner.
  EXPECT_EQ(s.triangle_count(), 2 * (2 * 40 * 40 + 4 * 40 * 4));
  EXPECT_EQ(s.vertex_count(), 41 * 41 * 5 - 39 * 39 * 3);
  EXPECT_NEAR(enclosed_volume_mm3(s.triangles, s.reference_mm), 100.0 * 100.0 * 10.0, 1e-6);
}

TEST(RenderSurface, TubeIsClosedGenusOneAndEnclosesTheAnnulusVolumeWithinThreePercent) {
  const TissueModel model = builtin_model("cylinder");
  const RenderSurface s = build_render_surface(model);
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.euler_characteristic(), 0);
  const double outer_mm = 42.0;
  const double inner_mm = 0.615 * outer_mm;
  const double length_mm = 26 * 4.0;
  const double annulus_mm3 = std::numbers::pi * (outer_mm * outer_mm - inner_mm * inner_mm) * length_mm;
  const double volume_mm3 = enclosed_volume_mm3(s.triangles, s.reference_mm);
  EXPECT_NEAR(volume_mm3 / annulus_mm3, 1.0, 0.03);
  // The voxelized body alone (cells x h^3) is further off than the sub-cell surface.
  const double voxels_mm3 = model.volume.cell_count() * 64.0;
  EXPECT_LT(std::abs(volume_mm3 - annulus_mm3), std::abs(voxels_mm3 - annulus_mm3));
}

TEST(RenderSurface, AbdomenShellIsOneClosedGenusZeroSurface) {
  const TissueModel model = builtin_model("abdomen");
  const RenderSurface s = build_render_surface(model);
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.euler_characteristic(), 2);
}

TEST(RenderSurface, SubCellVerticesLieOnTheCylinderSurfaces) {
  const TissueModel model = builtin_model("cylinder");
  const RenderSurface s = build_render_surface(model);
  // Vertices away from the end caps lie on r = 42 or r = 25.83 mm to a small fraction of h = 4 mm.
  double worst_mm = 0;
  for (const Vec3& p : s.reference_mm) {
    if (p.z() < 4.0 || p.z() > 100.0) continue;
    const double r = std::hypot(p.x() - 42.0, p.y() - 42.0);
    worst_mm = std::max(worst_mm, std::min(std::abs(r - 42.0), std::abs(r - 0.615 * 42.0)));
  }
  EXPECT_LT(worst_mm, 0.25 * 4.0);
}

TEST(RenderSurface, PlateCutThroughItsMiddleGivesTwoClosedSurfacesWithCutFaces) {
  TissueModel model = builtin_model("plate");
  model.volume.cut_links(links_across_x(model.volume, 20));
  const RenderSurface s = build_render_surface(model);
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.components, 2);
  EXPECT_EQ(t.euler_characteristic(), 4);
  int cut_triangles = 0;
  for (std::int32_t i = 0; i < s.triangle_count(); ++i) {
    if (!s.triangle_is_cut(i)) continue;
    ++cut_triangles;
    const Vec3i voxel = model.volume.cell_voxel(s.triangle_cell(i));
    EXPECT_TRUE((voxel.x() == 19 && s.triangle_face(i) == 1) || (voxel.x() == 20 && s.triangle_face(i) == 0));
  }
  EXPECT_EQ(cut_triangles, 2 * 2 * 40 * 4);  // both sides, 40x4 faces, two triangles each
  EXPECT_NEAR(enclosed_volume_mm3(s.triangles, s.reference_mm), 100.0 * 100.0 * 10.0, 1e-6);
}

TEST(RenderSurface, HalfDepthCutOpensTheSurfaceButKeepsOnePiece) {
  TissueModel model = builtin_model("plate");
  model.volume.cut_links(links_across_x(model.volume, 20, [](const Vec3i& v) { return v.z() >= 2 && v.y() >= 10 && v.y() < 30; }));
  const RenderSurface s = build_render_surface(model);
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented()) << t.open_edges << " open, " << t.non_manifold_edges << " non-manifold, "
                                       << t.misoriented_edges << " misoriented edges";
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.euler_characteristic(), 2);  // a slot in the top face keeps genus 0
}

TEST(RenderSurface, SingleCutFaceInsideTheBodyIsAClosedCrack) {
  // Both sides share all four corner vertices: they must take different diagonals.
  TissueModel model = builtin_model("plate");
  const CellId c = model.volume.cell_at_voxel({10, 10, 1});
  model.volume.cut_links(std::vector<CellFace>{{c, 5}});
  const RenderSurface s = build_render_surface(model);
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.components, 2);  // the plate's outside and the crack inside it
  EXPECT_EQ(t.euler_characteristic(), 4);
  EXPECT_NEAR(enclosed_volume_mm3(s.triangles, s.reference_mm), 100.0 * 100.0 * 10.0, 1e-6);
}

TEST(RenderSurface, CellsTouchingAlongAnEdgeOrAtAPointGiveSeparateClosedSurfaces) {
  const TissueModel edge = mask_model({2, 2, 1}, {{0, 0, 0}, {1, 1, 0}});
  const SurfaceTopology te = topology_of(build_render_surface(edge));
  EXPECT_TRUE(te.closed_and_oriented());
  EXPECT_EQ(te.components, 2);
  EXPECT_EQ(te.euler_characteristic(), 4);

  const TissueModel point = mask_model({2, 2, 2}, {{0, 0, 0}, {1, 1, 1}});
  const SurfaceTopology tp = topology_of(build_render_surface(point));
  EXPECT_TRUE(tp.closed_and_oriented());
  EXPECT_EQ(tp.components, 2);
}

TEST(RenderSurface, NonManifoldRingAroundACornerStaysClosed) {
  // Six of the eight cells around the centre corner; the two missing ones touch only at it.
  std::vector<Vec3i> voxels;
  for (int k = 0; k < 8; ++k)
    if (k != 2 && k != 5) voxels.push_back(corner_offset(k));
  const RenderSurface s = build_render_surface(mask_model({2, 2, 2}, voxels));
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.components, 1);
}

/// All voxels of a dims box except `missing`.
std::vector<Vec3i> box_voxels(const Vec3i& dims, const std::vector<Vec3i>& missing = {}) {
  std::vector<Vec3i> voxels;
  for (int z = 0; z < dims.z(); ++z)
    for (int y = 0; y < dims.y(); ++y)
      for (int x = 0; x < dims.x(); ++x)
        if (std::find(missing.begin(), missing.end(), Vec3i(x, y, z)) == missing.end()) voxels.push_back({x, y, z});
  return voxels;
}

TEST(RenderSurface, OneCellSlitFromTheOutsideIsClosedWhereItMeetsTheOutside) {
  // One cut face of a 2x2x3 box whose lower edge lies on the box's -y side and whose other three
  // edges are crack fronts (the demo's defect, reduced). Both ends of the edge on the outside are
  // unsplit linked-volume vertices, so material pairing used that surface edge twice on each side
  // of the cut (4 triangles). The simulation mesh holds both lips of the slit together there, and
  // so does the surface now: the outside passes over the slit, whose two faces close into a crack
  // inside the body.
  TissueModel model = mask_model({2, 2, 3}, box_voxels({2, 2, 3}));
  model.volume.cut_links(std::vector<CellFace>{{model.volume.cell_at_voxel({0, 0, 1}), 1}});
  const SurfaceTopology t = topology_of(build_render_surface(model));
  EXPECT_TRUE(t.closed_and_oriented()) << t.non_manifold_edges << " non-manifold, " << t.misoriented_edges
                                       << " misoriented";
  EXPECT_EQ(t.components, 2);  // the box's outside and the closed slit
  EXPECT_EQ(t.euler_characteristic(), 4);
}

TEST(RenderSurface, CellsTouchingAlongAnEdgeAndJoinedAtBothEndsShareThatEdge) {
  // The middle layer of a 2x2x3 box keeps two diagonal cells only; they touch along the vertical
  // centre edge and share the vertices at both its ends through the full layers above and below.
  // The surface joins them along that edge as the simulation mesh does: one closed sphere.
  const TissueModel model = mask_model({2, 2, 3}, box_voxels({2, 2, 3}, {{0, 0, 1}, {1, 1, 1}}));
  const SurfaceTopology t = topology_of(build_render_surface(model));
  EXPECT_TRUE(t.closed_and_oriented()) << t.non_manifold_edges << " non-manifold, " << t.misoriented_edges
                                       << " misoriented";
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.euler_characteristic(), 2);
}

TEST(RenderSurface, CrossOfFourSlitsAroundAnInnerEdgeGivesFourClosedCracks) {
  // The four links around the vertical centre edge of the middle layer of a 4x4x3 box: four
  // one-cell slits meeting at the edge, all cells sharing the vertices at both its ends through
  // the layers above and below. Each slit is closed along the edge (joined across the gaps in
  // ring order), so each is a closed crack of its own inside the body.
  TissueModel model = mask_model({4, 4, 3}, box_voxels({4, 4, 3}));
  const auto cell = [&](int x, int y) { return model.volume.cell_at_voxel({x, y, 1}); };
  model.volume.cut_links(std::vector<CellFace>{{cell(1, 1), 1}, {cell(1, 2), 1}, {cell(1, 1), 3}, {cell(2, 1), 3}});
  const SurfaceTopology t = topology_of(build_render_surface(model));
  EXPECT_TRUE(t.closed_and_oriented()) << t.non_manifold_edges << " non-manifold, " << t.misoriented_edges
                                       << " misoriented";
  EXPECT_EQ(t.components, 5);  // the box's outside and four cracks
  EXPECT_EQ(t.euler_characteristic(), 10);
}

TEST(RenderSurface, MaskModelIsSmoothedButClosed) {
  std::vector<Vec3i> voxels;
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) voxels.push_back({x, y, z});
  const TissueModel model = mask_model({8, 6, 3}, voxels);
  const RenderSurface s = build_render_surface(model);
  const SurfaceTopology t = topology_of(s);
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.euler_characteristic(), 2);
  // Flat faces stay (occupancy 1/2 there); edges and corners are rounded inwards a little.
  const double box_mm3 = 16.0 * 12.0 * 6.0;
  const double volume_mm3 = enclosed_volume_mm3(s.triangles, s.reference_mm);
  EXPECT_LT(volume_mm3, box_mm3);
  // No vertex moves more than a quarter cell (0.5 mm) along an axis: the box shrunk by that bounds it.
  EXPECT_GT(volume_mm3, (16.0 - 1.0) * (12.0 - 1.0) * (6.0 - 1.0));
}

TEST(RenderSurface, EmbeddingReproducesEveryVertexPosition) {
  const TissueModel model = builtin_model("cylinder");
  const RenderSurface s = build_render_surface(model);
  const double h = model.volume.grid().cell_size_mm;
  for (SurfaceVertexId v = 0; v < s.vertex_count(); ++v) {
    const auto i = static_cast<size_t>(v);
    const Vec3 lo = model.volume.grid().corner_position_mm(model.volume.cell_voxel(s.cell[i]));
    EXPECT_LT((lo + h * s.xi[i] - s.reference_mm[i]).norm(), 1e-9);
    EXPECT_GE(s.xi[i].minCoeff(), -0.5 - 1e-12);
    EXPECT_LE(s.xi[i].maxCoeff(), 1.5 + 1e-12);
  }
}

TEST(RenderSurface, RigidTranslationMovesEveryVertexByExactlyTheTranslation) {
  TissueModel model = builtin_model("cylinder");
  model.volume.cut_links(links_across_x(model.volume, 10, [](const Vec3i& v) { return v.y() < 5; }));
  const RenderSurface s = build_render_surface(model);
  const Vec3 t{1.5, -2.0, 0.25};
  const std::vector<Vec3> u(static_cast<size_t>(model.volume.vertex_count()), t);
  const std::vector<Vec3> x = deformed_positions(s, model.volume, u);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_LT((x[i] - s.reference_mm[i] - t).norm(), 1e-12);
}

TEST(RenderSurface, LinearDisplacementFieldIsReproducedExactly) {
  TissueModel model = builtin_model("abdomen");
  model.volume.cut_links(links_across_x(model.volume, 30, [](const Vec3i& v) { return v.z() > 10 && v.z() < 30; }));
  const RenderSurface s = build_render_surface(model);
  Mat3 a;
  a << 0.01, -0.02, 0.005, 0.03, -0.01, 0.0, 0.002, 0.004, 0.02;
  const Vec3 b{0.5, -1.0, 2.0};
  std::vector<Vec3> u(static_cast<size_t>(model.volume.vertex_count()));
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v)
    u[static_cast<size_t>(v)] = a * model.volume.vertex_position_mm(v) + b;
  const std::vector<Vec3> x = deformed_positions(s, model.volume, u);
  for (size_t i = 0; i < x.size(); ++i)
    EXPECT_LT((x[i] - (s.reference_mm[i] + a * s.reference_mm[i] + b)).norm(), 1e-9);
}

TEST(RenderSurface, DisplacementOfTheWrongSizeIsRefused) {
  const TissueModel model = builtin_model("plate");
  const RenderSurface s = build_render_surface(model);
  EXPECT_THROW(deformed_positions(s, model.volume, std::vector<Vec3>(3, Vec3::Zero())), InputError);
}

}  // namespace
}  // namespace cleave
