#include "studio/surface_residual.hpp"

#include <cstdint>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace cleave::studio {

std::vector<float> residual_per_surface_vertex(const LinkedVolume& volume, const SparseMatrix& divergence,
                                               std::span<const Vec6> stress_kPa, const RenderSurface& surface,
                                               std::span<const VertexId> held) {
  std::vector<float> out(static_cast<std::size_t>(surface.vertex_count()), 0.0f);
  if (stress_kPa.empty()) return out;
  // Only the rows of the surface's vertices, in parallel (the whole T sigma took ~3 ms at 45k cells).
  const Eigen::Map<const Vector> sigma(stress_kPa.data()->data(), 6 * static_cast<Eigen::Index>(stress_kPa.size()));
  std::vector<std::uint8_t> is_held(static_cast<std::size_t>(volume.vertex_count()), 0);
  for (VertexId v : held) is_held[static_cast<std::size_t>(v)] = 1;
  const double h = volume.grid().cell_size_mm;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t v = r.begin(); v < r.end(); ++v) {
      for (VertexId w : volume.cell_vertices(surface.cell[v])) {
        if (volume.vertex_grid_corner(w) != surface.grid_corner[v]) continue;
        if (is_held[static_cast<std::size_t>(w)] != 0) break;  // the support's reaction, not a residual
        const Eigen::Index row = 3 * static_cast<Eigen::Index>(w);
        const Vec3 force(divergence.row(row).dot(sigma), divergence.row(row + 1).dot(sigma), divergence.row(row + 2).dot(sigma));
        out[v] = static_cast<float>(force.norm() / (h * h));
        break;
      }
    }
  });
  return out;
}

}  // namespace cleave::studio
