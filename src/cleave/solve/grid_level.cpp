#include "cleave/solve/grid_level.hpp"

namespace cleave {

GridLevel grid_level_of(const LinkedVolume& volume) {
  GridLevel level;
  level.dims = volume.grid().dims;
  const auto cells = static_cast<std::size_t>(volume.cell_count());
  level.cell_voxel.resize(cells);
  level.cell_vertices.resize(cells);
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    level.cell_voxel[static_cast<std::size_t>(c)] = volume.cell_voxel(c);
    level.cell_vertices[static_cast<std::size_t>(c)] = volume.cell_vertices(c);
    for (Face f = 1; f < kFaceCount; f += 2)  // +x, +y, +z: each link once
      if (volume.linked(c, f)) level.links.push_back({c, volume.neighbor(c, f), f});
  }
  level.vertex_count = volume.vertex_count();
  return level;
}

}  // namespace cleave
