// Built-in shapes at the paper's resolutions (Table 1) and their analytic sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "cleave/core/error.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/shapes/builtin_shapes.hpp"

namespace cleave {
namespace {

struct PaperModel {
  const char* name;
  Vec3i resolution;
  int paper_cells;
  int paper_vertices;
};

class PaperResolution : public ::testing::TestWithParam<PaperModel> {};

TEST_P(PaperResolution, CellAndVertexCountsMatchTable1WithinTwoPercent) {
  const PaperModel& m = GetParam();
  const auto lv = LinkedVolume::from_labels(make_builtin_shape(m.name, {m.resolution, {}}));
  EXPECT_NEAR(lv.cell_count(), m.paper_cells, 0.02 * m.paper_cells);
  EXPECT_NEAR(lv.vertex_count(), m.paper_vertices, 0.02 * m.paper_vertices);
  EXPECT_EQ(lv.component_count(), 1);
}

INSTANTIATE_TEST_SUITE_P(Table1, PaperResolution,
                         ::testing::Values(PaperModel{"cylinder", {21, 21, 26}, 5550, 7540},
                                           PaperModel{"cylinder", {42, 42, 51}, 44000, 51714},
                                           PaperModel{"abdomen", {63, 21, 42}, 5734, 10189},
                                           PaperModel{"abdomen", {126, 41, 84}, 45313, 62481}));

TEST(BuiltinShapes, TubeVolumeConvergesToTheAnnulus) {
  // Outer diameter 84 mm, inner radius 0.615 of the outer, length = nz * h.
  double previous_error = 1.0;
  for (int n : {21, 42, 84}) {
    const LabelVolume v = make_builtin_shape("cylinder", {Vec3i{n, n, 8}, {}});
    const double h = v.grid.cell_size_mm;
    const double length = 8 * h;
    const double outer = 42.0, inner = 0.615 * 42.0;
    const double analytic = std::numbers::pi * (outer * outer - inner * inner) * length;
    const double voxels = static_cast<double>(v.inside_count()) * h * h * h;
    const double error = std::abs(voxels - analytic) / analytic;
    EXPECT_LT(error, 0.05) << "at " << n << " cells across";
    EXPECT_LT(error, previous_error + 1e-3) << "refinement must not make it worse";
    previous_error = error;
  }
}

TEST(BuiltinShapes, PlateIsFilledBoxOfFixedSize) {
  const LabelVolume v = make_builtin_shape("plate", {Vec3i{20, 20, 2}, {}});
  EXPECT_EQ(v.inside_count(), 20 * 20 * 2);
  EXPECT_DOUBLE_EQ(v.grid.cell_size_mm, 5.0);
}

TEST(BuiltinShapes, AbdomenHasSkinFatMuscleFromOutsideIn) {
  const LabelVolume v = make_builtin_shape("abdomen", {Vec3i{126, 41, 84}, {}});  // 2.5 mm cells resolve the 2 mm skin
  // Walk down the central column from above: the first inside voxel is skin, the last muscle.
  const int x = 63, z = 42;
  Label first = 0, last = 0;
  for (int y = v.grid.dims.y() - 1; y >= 0; --y) {
    const Label l = v.at({x, y, z});
    if (l == 0) continue;
    if (first == 0) first = l;
    last = l;
  }
  EXPECT_EQ(first, 1);
  EXPECT_EQ(last, 3);
  EXPECT_EQ(v.label_names.at(2), "fat");
}

TEST(BuiltinShapes, CornerDistanceIsNegativeExactlyInsideTheTube) {
  const LabelVolume v = make_builtin_shape("cylinder", {});
  ASSERT_TRUE(v.has_distance());
  const GridSpec& g = v.grid;
  const Vec3 centre = g.origin_mm + 0.5 * g.extent_mm();
  // Radius 0.8 * 42 mm lies inside the wall (between 25.8 and 42 mm); the axis lies in the hole.
  const Vec3i wall = g.voxel_of(centre + Vec3(0.8 * 42.0, 0, 0));
  const Vec3i hole = g.voxel_of(centre);
  EXPECT_LT(v.corner_distance_mm[static_cast<size_t>(g.corner_index(wall))], 0.0f);
  EXPECT_GT(v.corner_distance_mm[static_cast<size_t>(g.corner_index(hole))], 0.0f);
}

TEST(BuiltinShapes, ResolutionOrCellSizeSetsTheGrid) {
  EXPECT_EQ(make_builtin_shape("cylinder", {{}, 2.0}).grid.dims, Vec3i(42, 42, 52));
  EXPECT_EQ(builtin_default_resolution("abdomen"), Vec3i(63, 21, 42));
}

TEST(BuiltinShapes, BadRequestsGiveClearErrors) {
  try {
    make_builtin_shape("sphere", {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown built-in model 'sphere'; expected one of: cylinder, abdomen, plate");
  }
  try {
    make_builtin_shape("plate", {Vec3i{0, 4, 4}, {}});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "resolution 0x4x4: expected a positive number of cells along each axis");
  }
  EXPECT_THROW(make_builtin_shape("plate", {{}, -1.0}), InputError);
  // 100000^3 cells cannot fit: refused before allocating, saying how much it would need.
  try {
    make_builtin_shape("plate", {Vec3i{100000, 100000, 100000}, {}});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("would need"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cleave
