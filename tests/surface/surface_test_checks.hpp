#pragma once
// Checks shared by the render-surface tests: an incrementally updated surface equals a fresh build.
#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>
#include <vector>

#include "cleave/surface/render_surface.hpp"
#include "cleave/surface/surface_topology.hpp"

namespace cleave::test {

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

inline std::vector<QuadRecord> canonical(const RenderSurface& s) {
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
inline void expect_equal_to_fresh_build(const RenderSurface& updated, const TissueModel& model) {
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

}  // namespace cleave::test
