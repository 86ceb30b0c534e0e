// Property test of the render surface under random cuts: on a small box (with a few voxels
// missing, so that cells also touch along edges and at points), batches of random link cuts,
// one-cell slits from a grid plane, crosses of slits around one grid edge, isolated cells and
// crack tips. After every batch the incrementally updated surface must equal a fresh build and
// be closed, manifold and consistently oriented, with every vertex a single linked-volume vertex
// embedded in one of its cells.
//
// Components: every closed surface component bounds material of exactly one volume component,
// and every volume component has at least one. The counts are not equal in general: a piece
// with an enclosed cavity (an isolated cell inside the box leaves one) or a crack that reaches
// the outside nowhere (it is closed on all its edges, or only along grid edges whose both
// ends the linked volume holds together) has one closed surface per boundary shell. So the test
// asserts surface components >= volume components, with the map from surface components to
// volume components onto, and that every surface component is a closed orientable surface
// (even Euler characteristic of at most 2).
#include <gtest/gtest.h>

#include <algorithm>
#include <fmt/format.h>
#include <map>
#include <random>
#include <set>

#include "cleave/surface/corner_fans.hpp"
#include "cleave/surface/render_surface.hpp"
#include "cleave/surface/surface_topology.hpp"
#include "surface_test_checks.hpp"
#include "surface_test_models.hpp"

namespace cleave {
namespace {

constexpr int kConfigurations = 400;  ///< seeds; each runs kBatches cuts on a fresh box
constexpr int kBatches = 3;
const Vec3i kBoxDims{4, 3, 3};

/// Every link of the volume (once, from the cell on its lower side).
std::vector<CellFace> all_links(const LinkedVolume& volume) {
  std::vector<CellFace> links;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (Face f : {1, 3, 5})
      if (volume.neighbor(c, f) != kNone) links.push_back({c, f});
  return links;
}

/// Each link with probability p.
std::vector<CellFace> random_links(const LinkedVolume& volume, std::mt19937& rng, double p) {
  std::bernoulli_distribution pick(p);
  std::vector<CellFace> links;
  for (const CellFace& l : all_links(volume))
    if (pick(rng)) links.push_back(l);
  return links;
}

/// The links across one grid plane (normal axis and position random) within a random rectangle
/// of the plane, one or two cells on a side: a slit, which ends in crack tips where the
/// rectangle stops inside the box.
std::vector<CellFace> random_slit(const LinkedVolume& volume, std::mt19937& rng) {
  const int axis = std::uniform_int_distribution<int>(0, 2)(rng);
  const Face f = 2 * axis + 1;
  const Vec3i& dims = volume.grid().dims;
  const int plane = std::uniform_int_distribution<int>(0, dims[axis] - 2)(rng);
  Vec3i lo;
  Vec3i hi;
  for (int a = 0; a < 3; ++a) {
    if (a == axis) {
      lo[a] = hi[a] = plane;
      continue;
    }
    lo[a] = std::uniform_int_distribution<int>(0, dims[a] - 1)(rng);
    hi[a] = std::min(dims[a] - 1, lo[a] + std::uniform_int_distribution<int>(0, 1)(rng));
  }
  std::vector<CellFace> links;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Vec3i v = volume.cell_voxel(c);
    if ((v.array() >= lo.array()).all() && (v.array() <= hi.array()).all() && volume.neighbor(c, f) != kNone)
      links.push_back({c, f});
  }
  return links;
}

/// All links of one random cell.
std::vector<CellFace> isolated_cell(const LinkedVolume& volume, std::mt19937& rng) {
  const CellId c = std::uniform_int_distribution<CellId>(0, volume.cell_count() - 1)(rng);
  std::vector<CellFace> links;
  for (Face f = 0; f < kFaceCount; ++f)
    if (volume.neighbor(c, f) != kNone) links.push_back({c, f});
  return links;
}

/// The four links around one grid edge (a random edge of a random cell): a cross of one-cell
/// slits, whose four runs of cells around the edge may share the vertices at both its ends.
std::vector<CellFace> cross_around_edge(const LinkedVolume& volume, std::mt19937& rng) {
  const CellId c = std::uniform_int_distribution<CellId>(0, volume.cell_count() - 1)(rng);
  const int axis = std::uniform_int_distribution<int>(0, 2)(rng);
  const int u = (axis + 1) % 3;
  const int v = (axis + 2) % 3;
  // The edge of cell c along `axis` at its +u, +v corner; the ring is c and its +u, +v, +u+v cells.
  const Vec3i origin = volume.cell_voxel(c);
  const Vec3i du = corner_offset(1 << u);
  const Vec3i dv = corner_offset(1 << v);
  std::vector<CellFace> links;
  const auto link = [&](const Vec3i& voxel, int a) {
    const CellId cell = volume.cell_at_voxel(voxel);
    if (cell != kNone && volume.neighbor(cell, 2 * a + 1) != kNone) links.push_back({cell, 2 * a + 1});
  };
  link(origin, u);
  link(origin, v);
  link(origin + dv, u);
  link(origin + du, v);
  return links;
}

std::vector<CellFace> random_cut(const LinkedVolume& volume, std::mt19937& rng) {
  switch (std::uniform_int_distribution<int>(0, 4)(rng)) {
    case 0: return random_slit(volume, rng);
    case 1: return isolated_cell(volume, rng);
    case 4: return cross_around_edge(volume, rng);
    case 2: return random_links(volume, rng, 0.05);
    default: return random_links(volume, rng, 0.25);
  }
}

/// The box with each voxel missing with probability 1/10 (at least one voxel kept).
TissueModel random_box(std::mt19937& rng) {
  std::bernoulli_distribution missing(0.1);
  std::vector<Vec3i> voxels;
  for (int z = 0; z < kBoxDims.z(); ++z)
    for (int y = 0; y < kBoxDims.y(); ++y)
      for (int x = 0; x < kBoxDims.x(); ++x)
        if (!missing(rng)) voxels.push_back({x, y, z});
  if (voxels.empty()) voxels.push_back({0, 0, 0});
  return test::mask_model(kBoxDims, voxels);
}

/// Closed, manifold, oriented; vertices are single linked-volume vertices embedded in a cell
/// of their fan; surface components map onto volume components.
void expect_surface_invariants(const RenderSurface& s, const LinkedVolume& volume) {
  const SurfaceTopology t = surface_topology(s.triangles, s.vertex_count());
  ASSERT_TRUE(t.closed_and_oriented()) << t.open_edges << " open, " << t.non_manifold_edges << " non-manifold, "
                                       << t.misoriented_edges << " misoriented edges";
  EXPECT_EQ(t.vertices, s.vertex_count());

  // Every slot of every quad names the same grid corner and linked-volume vertex as its vertex.
  std::vector<VertexId> volume_vertex(static_cast<size_t>(s.vertex_count()), kNone);
  for (const SurfaceQuad& q : s.quads)
    for (int slot = 0; slot < 4; ++slot) {
      const auto v = static_cast<size_t>(q.vertices[static_cast<size_t>(slot)]);
      const int corner = quad_corner(q.face, slot);
      EXPECT_EQ(s.grid_corner[v], volume.cell_voxel(q.cell) + corner_offset(corner));
      const VertexId w = volume.corner_vertex(q.cell, corner);
      if (volume_vertex[v] == kNone) volume_vertex[v] = w;
      EXPECT_EQ(volume_vertex[v], w) << "surface vertex " << v << " joins two linked-volume vertices";
    }
  // The embedding cell has the vertex's linked-volume vertex at the vertex's grid corner.
  const double h = volume.grid().cell_size_mm;
  for (size_t v = 0; v < s.reference_mm.size(); ++v) {
    const Vec3i offset = s.grid_corner[v] - volume.cell_voxel(s.cell[v]);
    ASSERT_TRUE(offset.minCoeff() >= 0 && offset.maxCoeff() <= 1);
    EXPECT_EQ(volume.corner_vertex(s.cell[v], offset.x() | (offset.y() << 1) | (offset.z() << 2)), volume_vertex[v]);
    const Vec3 lo = volume.grid().corner_position_mm(volume.cell_voxel(s.cell[v]));
    EXPECT_LT((lo + h * s.xi[v] - s.reference_mm[v]).norm(), 1e-9);
  }

  // Surface components (through shared vertices) -> volume components.
  std::vector<int> parent(static_cast<size_t>(s.vertex_count()));
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  const auto find = [&](int v) {
    while (parent[static_cast<size_t>(v)] != v) v = parent[static_cast<size_t>(v)];
    return v;
  };
  for (const auto& tri : s.triangles)
    for (int i = 1; i < 3; ++i) parent[static_cast<size_t>(find(tri[static_cast<size_t>(i)]))] = find(tri[0]);
  std::map<int, int> piece_of_surface;
  std::map<int, std::vector<std::array<std::int32_t, 3>>> triangles_of_surface;
  for (std::int32_t tr = 0; tr < s.triangle_count(); ++tr) {
    const int root = find(s.triangles[static_cast<size_t>(tr)][0]);
    const int piece = volume.cell_components()[static_cast<size_t>(s.triangle_cell(tr))];
    const auto [it, inserted] = piece_of_surface.emplace(root, piece);
    EXPECT_EQ(it->second, piece) << "one closed surface bounds two volume components";
    triangles_of_surface[root].push_back(s.triangles[static_cast<size_t>(tr)]);
  }
  std::set<int> pieces;
  for (const auto& [root, piece] : piece_of_surface) pieces.insert(piece);
  EXPECT_EQ(static_cast<int>(pieces.size()), volume.component_count()) << "a volume component without a surface";
  EXPECT_GE(t.components, volume.component_count());
  for (const auto& [root, triangles] : triangles_of_surface) {
    const std::int64_t chi = surface_topology(triangles, s.vertex_count()).euler_characteristic();
    EXPECT_TRUE(chi <= 2 && chi % 2 == 0) << "a closed surface with Euler characteristic " << chi;
  }
}

TEST(RenderSurfaceRandomCuts, EveryCutStateGivesAClosedManifoldSurfaceAndUpdatesMatchFreshBuilds) {
  for (int seed = 0; seed < kConfigurations; ++seed) {
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937 rng(static_cast<std::mt19937::result_type>(seed));
    TissueModel model = random_box(rng);
    RenderSurface s = build_render_surface(model);
    expect_surface_invariants(s, model.volume);
    for (int batch = 0; batch < kBatches; ++batch) {
      SCOPED_TRACE(fmt::format("batch {}", batch));
      const std::vector<CellFace> links = random_cut(model.volume, rng);
      update_render_surface(s, model, model.volume.cut_links(links));
      expect_surface_invariants(s, model.volume);
      test::expect_equal_to_fresh_build(s, model);
      if (::testing::Test::HasFailure()) return;  // one configuration's report is enough
    }
  }
}

}  // namespace
}  // namespace cleave
