// The residual the page shows per surface vertex (apps/studio/surface_residual.hpp) equals the
// whole product T sigma read at each surface vertex's model vertex, and is 0 at held vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cleave/shapes/builtin_shapes.hpp"
#include "cleave/stress/equilibrium_operator.hpp"
#include "studio/surface_residual.hpp"

namespace cleave::studio {
namespace {

TEST(SurfaceResidual, EqualsTheWholeProductAtEachSurfaceVertex) {
  ShapeResolution resolution;
  resolution.cells = Vec3i(12, 12, 14);
  const TissueModel model = make_tissue_model("cylinder", make_builtin_shape("cylinder", resolution), {{Label{1}, Material{}}});
  const LinkedVolume& volume = model.volume;
  std::vector<Vec6> stress(static_cast<std::size_t>(volume.cell_count()));
  for (std::size_t c = 0; c < stress.size(); ++c)
    for (int k = 0; k < 6; ++k) stress[c][k] = 10.0 * std::sin(0.37 * static_cast<double>(c) + 1.3 * k);
  std::vector<VertexId> held;
  for (VertexId v = 0; v < volume.vertex_count(); v += 7) held.push_back(v);
  const SparseMatrix divergence = stress_divergence_matrix(volume);
  const RenderSurface surface = build_render_surface(model);
  const std::vector<float> shown = residual_per_surface_vertex(volume, divergence, stress, surface, held);
  ASSERT_EQ(shown.size(), static_cast<std::size_t>(surface.vertex_count()));

  const Vector force = divergence * flatten_stress(stress);
  const double h = volume.grid().cell_size_mm;
  int held_seen = 0, nonzero = 0;
  for (std::size_t v = 0; v < shown.size(); ++v) {
    VertexId w = kNone;
    for (VertexId x : volume.cell_vertices(surface.cell[v]))
      if (volume.vertex_grid_corner(x) == surface.grid_corner[v]) w = x;
    ASSERT_NE(w, kNone);
    if (std::binary_search(held.begin(), held.end(), w)) {
      EXPECT_EQ(shown[v], 0.0f) << "a held vertex shows no residual (its force is the support's)";
      ++held_seen;
      continue;
    }
    const double expected = force.segment<3>(3 * static_cast<Eigen::Index>(w)).norm() / (h * h);
    EXPECT_NEAR(shown[v], expected, 1e-5 * (1.0 + expected)) << "surface vertex " << v;
    if (expected > 1e-3) ++nonzero;
  }
  EXPECT_GT(held_seen, 0);
  EXPECT_GT(nonzero, static_cast<int>(shown.size()) / 2) << "an unbalanced field leaves a residual almost everywhere";
  EXPECT_EQ(residual_per_surface_vertex(volume, divergence, {}, surface, held), std::vector<float>(shown.size(), 0.0f));
}

}  // namespace
}  // namespace cleave::studio
