#include "cleave/pipeline/held_vertices.hpp"

#include <algorithm>
#include <cstdint>

#include "cleave/cut/surface_side_vertices.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/grid/vertices_only_of.hpp"

namespace cleave {

std::vector<VertexId> held_vertices(const TissueModel& model, const SimulationSettings& s) {
  const LinkedVolume& volume = model.volume;
  std::vector<std::uint8_t> held(static_cast<std::size_t>(volume.vertex_count()), 0);
  for (const FixedBox& box : s.fixed_boxes)
    for (const VertexId v : vertices_in_box(volume, box.lo_mm, box.hi_mm)) held[static_cast<std::size_t>(v)] = 1;
  if (!s.fixed_surfaces.empty()) {
    const BodySurface surface(model);
    for (const FixedSurface side : s.fixed_surfaces) {
      const SurfaceSide which = side == FixedSurface::inner ? SurfaceSide::inner : SurfaceSide::all;
      for (const VertexId v : surface_side_vertices(surface, which)) held[static_cast<std::size_t>(v)] = 1;
    }
  }
  std::vector<VertexId> out;
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (held[static_cast<std::size_t>(v)]) out.push_back(v);
  return out;
}

std::vector<VertexId> held_vertices(const TissueModel& model, const SimulationSettings& settings,
                                    std::span<const CellId> removed_cells) {
  std::vector<VertexId> out = held_vertices(model, settings);
  const std::vector<VertexId> removed = vertices_only_of(model.volume, removed_cells);
  const auto supports_end = static_cast<std::ptrdiff_t>(out.size());
  out.insert(out.end(), removed.begin(), removed.end());
  std::inplace_merge(out.begin(), out.begin() + supports_end, out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace cleave
