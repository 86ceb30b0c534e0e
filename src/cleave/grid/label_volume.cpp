#include "cleave/grid/label_volume.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/core/memory_budget.hpp"

namespace cleave {

std::int64_t LabelVolume::inside_count() const {
  return std::count_if(labels.begin(), labels.end(), [](Label l) { return l != 0; });
}

LabelVolume make_empty_label_volume(const GridSpec& grid, bool with_distance) {
  if (grid.dims.minCoeff() <= 0)
    throw InputError(fmt::format("grid dimensions {}x{}x{}: expected at least one cell along each axis", grid.dims.x(),
                                 grid.dims.y(), grid.dims.z()));
  if (!(grid.cell_size_mm > 0) || !std::isfinite(grid.cell_size_mm))
    throw InputError(fmt::format("cell size {} mm: expected a positive finite number", grid.cell_size_mm));
  // Labels + voxel-to-cell map + (up to) one cell record per voxel, ~100 bytes each in the worst case.
  const auto voxels = static_cast<std::uint64_t>(grid.voxel_count());
  require_memory(voxels * 110 + (with_distance ? static_cast<std::uint64_t>(grid.corner_count()) * 4 : 0),
                 fmt::format("a {}x{}x{} grid", grid.dims.x(), grid.dims.y(), grid.dims.z()));
  LabelVolume volume;
  volume.grid = grid;
  volume.labels.assign(voxels, Label{0});
  if (with_distance) volume.corner_distance_mm.assign(static_cast<size_t>(grid.corner_count()), 1.0f);
  return volume;
}

}  // namespace cleave
