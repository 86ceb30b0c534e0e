#include "cleave/grid/vertex_corner_slots.hpp"

namespace cleave {

VertexCornerSlots vertex_corner_slots(const LinkedVolume& volume, std::int32_t stride) {
  const auto& around = volume.vertex_cells();
  VertexCornerSlots out;
  out.start.assign(around.size() + 1, 0);
  for (std::size_t v = 0; v < around.size(); ++v) out.start[v + 1] = out.start[v] + static_cast<std::int32_t>(around[v].size());
  out.slot.resize(static_cast<std::size_t>(out.start.back()));
  for (std::size_t v = 0; v < around.size(); ++v)
    for (std::size_t t = 0; t < around[v].size(); ++t) {
      const CellId c = around[v][t];
      const auto& corners = volume.cell_vertices(c);
      int a = 0;
      while (corners[static_cast<std::size_t>(a)] != static_cast<VertexId>(v)) ++a;
      out.slot[static_cast<std::size_t>(out.start[v]) + t] = stride * static_cast<std::int32_t>(c) + a;
    }
  return out;
}

}  // namespace cleave
