// Incremental update after a cut equals a fresh build of the cut model.
#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>

#include "cleave/core/error.hpp"
#include "cleave/surface/render_surface.hpp"
#include "cleave/surface/surface_topology.hpp"
#include "surface_test_models.hpp"

namespace cleave {
namespace {

using test::builtin_model;
using test::links_across_x;

/// A quad with its vertices resolved to positions and embeddings, independent of id order.
struct QuadRecord {
  CellId cell;
  Face face;
  bool is_cut;
  int diagonal;
  std::array<std::array<double, 3>, 4> position;
  std::array<CellId, 4> vertex_cell;
  std::array<std::array<double, 3>, 4> xi;
  auto key() const { return std::tie(cell, face); }
  bool operator==(const QuadRecord&) const = default;
};

std::vector<QuadRecord> canonical(const RenderSurface& s) {
  std::vector<QuadRecord> records;
  for (const SurfaceQuad& q : s.quads) {
    QuadRecord r{q.cell, q.face, q.is_cut, q.diagonal, {}, {}, {}};
    for (size_t i = 0; i < 4; ++i) {
      const auto v = static_cast<size_t>(q.vertices[i]);
      for (int a = 0; a < 3; ++a) {
        r.position[i][static_cast<size_t>(a)] = s.reference_mm[v][a];
        r.xi[i][static_cast<size_t>(a)] = s.xi[v][a];
      }
      r.vertex_cell[i] = s.cell[v];
    }
    records.push_back(r);
  }
  std::sort(records.begin(), records.end(), [](const QuadRecord& a, const QuadRecord& b) { return a.key() < b.key(); });
  return records;
}

/// The updated surface is the fresh build, and its bookkeeping is consistent.
void expect_equal_to_fresh_build(const RenderSurface& updated, const TissueModel& model) {
  const RenderSurface fresh = build_render_surface(model);
  EXPECT_EQ(updated.vertex_count(), fresh.vertex_count());
  EXPECT_EQ(updated.triangle_count(), fresh.triangle_count());
  EXPECT_TRUE(canonical(updated) == canonical(fresh));
  const SurfaceTopology t = surface_topology(updated.triangles, updated.vertex_count());
  EXPECT_TRUE(t.closed_and_oriented());
  EXPECT_EQ(t.vertices, updated.vertex_count());  // no vertex left unused
  for (size_t q = 0; q < updated.quads.size(); ++q)
    EXPECT_EQ(updated.quad_of_face[static_cast<size_t>(updated.quads[q].cell) * 6 + static_cast<size_t>(updated.quads[q].face)],
              static_cast<std::int32_t>(q));
  // Each triangle pair is the quad split along its diagonal.
  for (size_t q = 0; q < updated.quads.size(); ++q) {
    const auto& v = updated.quads[q].vertices;
    EXPECT_TRUE(updated.triangles[2 * q][0] == v[0] && updated.triangles[2 * q + 1][2] == v[3]);
  }
}

TEST(UpdateRenderSurface, SequenceOfCutsInTheTubeMatchesFreshBuilds) {
  TissueModel model = builtin_model("cylinder");
  RenderSurface s = build_render_surface(model);
  const auto cut = [&](auto&& links) {
    const CutReport report = model.volume.cut_links(links);
    update_render_surface(s, model, report);
    expect_equal_to_fresh_build(s, model);
  };
  // A slot from the outside, half way through the wall.
  cut(links_across_x(model.volume, 10, [](const Vec3i& v) { return v.y() < 3 && v.z() >= 8 && v.z() < 14; }));
  // A perpendicular slot meeting it (staircase corner, vertices split again).
  std::vector<CellFace> across_y;
  for (CellId c = 0; c < model.volume.cell_count(); ++c) {
    const Vec3i v = model.volume.cell_voxel(c);
    if (v.y() == 2 && v.x() >= 6 && v.x() < 10 && v.z() >= 8 && v.z() < 14) across_y.push_back({c, 3});
  }
  cut(across_y);
  // Cutting the same links again changes nothing.
  cut(links_across_x(model.volume, 10, [](const Vec3i& v) { return v.y() < 3 && v.z() >= 8 && v.z() < 14; }));
  // Through the whole wall along the tube: the tube opens into a C.
  cut(links_across_x(model.volume, 10, [](const Vec3i& v) { return v.y() < 10; }));
  EXPECT_EQ(surface_topology(s.triangles, s.vertex_count()).euler_characteristic(), 2);
}

TEST(UpdateRenderSurface, CuttingThePlateInTwoMatchesAFreshBuild) {
  TissueModel model = builtin_model("plate");
  RenderSurface s = build_render_surface(model);
  update_render_surface(s, model, model.volume.cut_links(links_across_x(model.volume, 20)));
  expect_equal_to_fresh_build(s, model);
  EXPECT_EQ(surface_topology(s.triangles, s.vertex_count()).components, 2);
}

TEST(UpdateRenderSurface, CutInTheAbdomenMatchesAFreshBuild) {
  TissueModel model = builtin_model("abdomen");
  RenderSurface s = build_render_surface(model);
  update_render_surface(s, model, model.volume.cut_links(links_across_x(model.volume, 31, [](const Vec3i& v) {
                                    return v.z() >= 15 && v.z() < 25;
                                  })));
  expect_equal_to_fresh_build(s, model);
}

TEST(UpdateRenderSurface, VoxelMaskModelUpdateMatchesAFreshBuild) {
  std::vector<Vec3i> voxels;
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 10; ++x)
        if ((x - 5) * (x - 5) + (y - 3) * (y - 3) < 12) voxels.push_back({x, y, z});
  TissueModel model = test::mask_model({10, 6, 4}, voxels);
  RenderSurface s = build_render_surface(model);
  update_render_surface(s, model, model.volume.cut_links(links_across_x(model.volume, 5, [](const Vec3i& v) { return v.z() >= 2; })));
  expect_equal_to_fresh_build(s, model);
}

TEST(UpdateRenderSurface, SurfaceOfAnotherModelIsRefused) {
  const TissueModel plate = builtin_model("plate");
  TissueModel tube = builtin_model("cylinder");
  RenderSurface s = build_render_surface(plate);
  const CutReport report = tube.volume.cut_links(links_across_x(tube.volume, 10));
  EXPECT_THROW(update_render_surface(s, tube, report), ComputeError);
}

}  // namespace
}  // namespace cleave
