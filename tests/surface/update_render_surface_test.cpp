// Incremental update after a cut equals a fresh build of the cut model.
#include <gtest/gtest.h>

#include "cleave/core/error.hpp"
#include "cleave/surface/render_surface.hpp"
#include "cleave/surface/surface_topology.hpp"
#include "surface_test_checks.hpp"
#include "surface_test_models.hpp"

namespace cleave {
namespace {

using test::builtin_model;
using test::expect_equal_to_fresh_build;
using test::links_across_x;

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

TEST(UpdateRenderSurface, SlitGrowingFromOneCellToAThroughCutMatchesFreshBuilds) {
  // A 3x2x3 box. A single cut face with one edge on the -y side is a one-cell slit, closed where
  // it meets the outside (corner_fans.hpp); cutting on splits the vertices at the ends of that
  // edge and the slit opens, then it goes through the box and two pieces give two surfaces.
  std::vector<Vec3i> voxels;
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) voxels.push_back({x, y, z});
  TissueModel model = test::mask_model({3, 2, 3}, voxels);
  RenderSurface s = build_render_surface(model);
  const auto cut = [&](std::vector<Vec3i> lower_cells) {
    std::vector<CellFace> links;
    for (const Vec3i& v : lower_cells) links.push_back({model.volume.cell_at_voxel(v), 1});
    update_render_surface(s, model, model.volume.cut_links(links));
    expect_equal_to_fresh_build(s, model);
    return surface_topology(s.triangles, s.vertex_count());
  };
  EXPECT_EQ(cut({{0, 0, 1}}).components, 2);  // the outside and the closed slit
  EXPECT_EQ(cut({{0, 0, 2}}).components, 1);  // open to the top: one surface again
  const SurfaceTopology through = cut({{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 1, 2}});
  EXPECT_EQ(through.components, 2);
  EXPECT_EQ(model.volume.component_count(), 2);
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
