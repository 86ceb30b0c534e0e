// The linked volume: vertex sharing, splitting by cuts, components, incremental cutting.
#include <gtest/gtest.h>

#include <set>

#include "cleave/core/error.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/shapes/builtin_shapes.hpp"

namespace cleave {
namespace {

LabelVolume box_volume(Vec3i dims) {
  GridSpec grid;
  grid.dims = dims;
  grid.cell_size_mm = 2.0;
  LabelVolume v = make_empty_label_volume(grid, false);
  std::fill(v.labels.begin(), v.labels.end(), Label{1});
  return v;
}

/// All links crossing the plane x = (plane_x) in grid corners, i.e. between voxel columns plane_x-1 and plane_x.
std::vector<CellFace> links_across_x(const LinkedVolume& lv, int plane_x) {
  std::vector<CellFace> links;
  for (CellId c = 0; c < lv.cell_count(); ++c)
    if (lv.cell_voxel(c).x() == plane_x - 1 && lv.neighbor(c, 1) != kNone) links.push_back({c, 1});
  return links;
}

TEST(LinkedVolume, UncutBoxHasOneVertexPerGridCorner) {
  const auto lv = LinkedVolume::from_labels(box_volume({4, 3, 2}));
  EXPECT_EQ(lv.cell_count(), 24);
  EXPECT_EQ(lv.vertex_count(), 5 * 4 * 3);
  EXPECT_EQ(lv.component_count(), 1);
  // Links: (nx-1) ny nz + nx (ny-1) nz + nx ny (nz-1)
  EXPECT_EQ(lv.link_count(), 3 * 3 * 2 + 4 * 2 * 2 + 4 * 3 * 1);
  // Neighbouring cells share the four vertices of their common face.
  const CellId a = lv.cell_at_voxel({1, 1, 0});
  const CellId b = lv.cell_at_voxel({2, 1, 0});
  for (int k : face_corners(1)) EXPECT_EQ(lv.corner_vertex(a, k), lv.corner_vertex(b, k ^ 1));
}

TEST(LinkedVolume, VertexPositionsAreGridCorners) {
  const auto lv = LinkedVolume::from_labels(box_volume({2, 2, 2}));
  for (CellId c = 0; c < lv.cell_count(); ++c)
    for (int k = 0; k < 8; ++k) {
      const Vec3 expected = lv.grid().corner_position_mm(lv.cell_voxel(c) + corner_offset(k));
      EXPECT_EQ(lv.vertex_position_mm(lv.corner_vertex(c, k)), expected);
    }
}

TEST(LinkedVolume, CuttingPlateThroughMiddleGivesTwoComponentsAndDuplicatesExactlyThePlaneVertices) {
  const Vec3i dims{8, 6, 2};
  auto lv = LinkedVolume::from_labels(box_volume(dims));
  const VertexId before = lv.vertex_count();
  const auto links = links_across_x(lv, 4);
  ASSERT_EQ(links.size(), 6u * 2u);
  const CutReport report = lv.cut_links(links);

  EXPECT_EQ(report.links_cut, 12);
  EXPECT_EQ(lv.component_count(), 2);
  // The plane x = 4 holds (ny+1)(nz+1) grid corners; each gets exactly one extra vertex.
  const int plane_corners = (dims.y() + 1) * (dims.z() + 1);
  EXPECT_EQ(lv.vertex_count(), before + plane_corners);
  ASSERT_EQ(report.splits.size(), static_cast<size_t>(plane_corners));
  for (const VertexSplit& s : report.splits) {
    EXPECT_EQ(s.created.size(), 1u);
    EXPECT_EQ(lv.vertex_grid_corner(s.original).x(), 4);
    EXPECT_EQ(lv.vertex_grid_corner(s.created[0]), lv.vertex_grid_corner(s.original));
  }
  // No vertex is shared between the two halves any more.
  std::set<VertexId> left, right;
  for (CellId c = 0; c < lv.cell_count(); ++c)
    for (VertexId v : lv.cell_vertices(c)) (lv.cell_voxel(c).x() < 4 ? left : right).insert(v);
  for (VertexId v : left) EXPECT_EQ(right.count(v), 0u);
  EXPECT_EQ(lv.link_count() + lv.cut_link_count(), 7 * 6 * 2 + 8 * 5 * 2 + 8 * 6 * 1);
}

TEST(LinkedVolume, PartialCutSplitsOnlyWhereCellsAreDisconnectedAroundTheCorner) {
  auto lv = LinkedVolume::from_labels(box_volume({4, 4, 1}));
  // Cut the links across x = 2 for the cells with y = 0 and y = 1 only (half-way slit).
  std::vector<CellFace> links;
  for (CellId c = 0; c < lv.cell_count(); ++c)
    if (lv.cell_voxel(c).x() == 1 && lv.cell_voxel(c).y() < 2) links.push_back({c, 1});
  const VertexId before = lv.vertex_count();
  const CutReport report = lv.cut_links(links);
  EXPECT_EQ(lv.component_count(), 1);
  // Corners at x = 2, y = 0 and y = 1 (z = 0 and 1) split; the slit tip at y = 2 stays shared.
  EXPECT_EQ(lv.vertex_count(), before + 4);
  EXPECT_EQ(report.splits.size(), 4u);
  for (const VertexSplit& s : report.splits) EXPECT_LT(lv.vertex_grid_corner(s.original).y(), 2);
}

TEST(LinkedVolume, CuttingIsIncrementalAndIdempotent) {
  auto lv = LinkedVolume::from_labels(box_volume({6, 6, 6}));
  const CellId c = lv.cell_at_voxel({2, 2, 2});
  const CutReport first = lv.cut_links(std::vector<CellFace>{{c, 3}});
  EXPECT_EQ(first.links_cut, 1);
  EXPECT_TRUE(first.splits.empty());  // an interior face cut alone leaves every corner connected
  EXPECT_TRUE(lv.is_cut(c, 3));
  EXPECT_TRUE(lv.is_cut(lv.neighbor(c, 3), 2));
  const CutReport again = lv.cut_links(std::vector<CellFace>{{c, 3}});
  EXPECT_EQ(again.links_cut, 0);
  EXPECT_EQ(lv.vertex_count(), 7 * 7 * 7);
}

TEST(LinkedVolume, IsolatingOneCellGivesItEightOwnVertices) {
  auto lv = LinkedVolume::from_labels(box_volume({3, 3, 3}));
  const CellId c = lv.cell_at_voxel({1, 1, 1});
  std::vector<CellFace> links;
  for (Face f = 0; f < 6; ++f) links.push_back({c, f});
  lv.cut_links(links);
  EXPECT_EQ(lv.component_count(), 2);
  EXPECT_EQ(lv.vertex_count(), 4 * 4 * 4 + 8);
  for (VertexId v : lv.cell_vertices(c)) EXPECT_EQ(lv.vertex_cells()[static_cast<size_t>(v)].size(), 1u);
}

TEST(LinkedVolume, EdgeContactCellsDoNotShareTheirEdgeVertices) {
  // Two cells touching only along an edge are not linked, so they share no vertex.
  GridSpec grid;
  grid.dims = {2, 2, 1};
  LabelVolume v = make_empty_label_volume(grid, false);
  v.labels[static_cast<size_t>(grid.voxel_index({0, 0, 0}))] = 1;
  v.labels[static_cast<size_t>(grid.voxel_index({1, 1, 0}))] = 1;
  const auto lv = LinkedVolume::from_labels(v);
  EXPECT_EQ(lv.component_count(), 2);
  EXPECT_EQ(lv.vertex_count(), 16);
}

TEST(LinkedVolume, RejectsBadLinksAndEmptyVolumes) {
  auto lv = LinkedVolume::from_labels(box_volume({2, 2, 2}));
  EXPECT_THROW(lv.cut_links(std::vector<CellFace>{{99, 0}}), InputError);
  EXPECT_THROW(lv.cut_links(std::vector<CellFace>{{0, 6}}), InputError);
  GridSpec grid;
  grid.dims = {2, 2, 2};
  try {
    LinkedVolume::from_labels(make_empty_label_volume(grid, false));
    FAIL() << "an empty volume must be refused";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "the model has no cell inside the body (empty mask or shape)");
  }
}

TEST(LinkedVolume, MemoryPerCellIsWellUnderOneKilobyte) {
  const auto lv = LinkedVolume::from_labels(make_builtin_shape("abdomen", {Vec3i{126, 41, 84}, {}}));
  EXPECT_LT(static_cast<double>(lv.bytes()) / lv.cell_count(), 300.0);
}

}  // namespace
}  // namespace cleave
