// vertices_only_of: the corners a set of cells owns alone, before and after a cut.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/grid/vertices_only_of.hpp"

namespace cleave {
namespace {

LinkedVolume box(Vec3i dims) {
  GridSpec grid;
  grid.dims = dims;
  grid.cell_size_mm = 1.0;
  LabelVolume v = make_empty_label_volume(grid, false);
  std::fill(v.labels.begin(), v.labels.end(), Label{1});
  return LinkedVolume::from_labels(v);
}

std::vector<CellId> cells_with_x_below(const LinkedVolume& lv, int x) {
  std::vector<CellId> out;
  for (CellId c = 0; c < lv.cell_count(); ++c)
    if (lv.cell_voxel(c).x() < x) out.push_back(c);
  return out;
}

TEST(VerticesOnlyOf, ConnectedCellsOwnTheirCornersExceptThoseSharedAcrossTheBoundary) {
  const LinkedVolume lv = box({4, 2, 2});
  const std::vector<CellId> left = cells_with_x_below(lv, 2);  // 2 of 4 columns of cells
  // Corner planes x = 0 and x = 1 belong to the left half alone; x = 2 is shared with the right.
  EXPECT_EQ(vertices_only_of(lv, left).size(), 2u * 3u * 3u);
  EXPECT_TRUE(vertices_only_of(lv, {}).empty());
  std::vector<CellId> all(static_cast<std::size_t>(lv.cell_count()));
  for (CellId c = 0; c < lv.cell_count(); ++c) all[static_cast<std::size_t>(c)] = c;
  EXPECT_EQ(static_cast<VertexId>(vertices_only_of(lv, all).size()), lv.vertex_count());
}

TEST(VerticesOnlyOf, APieceCutFreeOwnsAllItsCornersAndTheRestKeepsTheirs) {
  LinkedVolume lv = box({4, 2, 2});
  std::vector<CellFace> links;
  for (CellId c = 0; c < lv.cell_count(); ++c)
    if (lv.cell_voxel(c).x() == 1) links.push_back({c, 1});
  lv.cut_links(links);
  const std::vector<CellId> left = cells_with_x_below(lv, 2);
  const std::vector<VertexId> owned = vertices_only_of(lv, left);
  EXPECT_EQ(owned.size(), 3u * 3u * 3u);  // the cut plane's corners were split: the left copy is its own
  EXPECT_TRUE(std::is_sorted(owned.begin(), owned.end()));
  EXPECT_EQ(lv.vertex_count(), 5 * 3 * 3 + 3 * 3);
}

TEST(VerticesOnlyOf, ACellOutsideTheVolumeIsNamed) {
  const LinkedVolume lv = box({2, 2, 2});
  const std::vector<CellId> bad = {0, 8};
  try {
    vertices_only_of(lv, bad);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "cell 8 is not in the volume; expected 0 to 7");
  }
}

}  // namespace
}  // namespace cleave
