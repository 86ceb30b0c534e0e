#pragma once
// Models and cuts shared by the render-surface tests.
#include <vector>

#include "cleave/model/tissue_model.hpp"
#include "cleave/shapes/builtin_shapes.hpp"

namespace cleave::test {

inline TissueModel builtin_model(const char* name) { return make_tissue_model(name, make_builtin_shape(name)); }

/// A voxel-mask model (no corner distances): label 1 at every listed voxel of a dims grid, h = 2 mm.
inline TissueModel mask_model(const Vec3i& dims, const std::vector<Vec3i>& voxels) {
  GridSpec grid;
  grid.dims = dims;
  grid.cell_size_mm = 2.0;
  LabelVolume labels = make_empty_label_volume(grid, false);
  for (const Vec3i& v : voxels) labels.labels[static_cast<size_t>(grid.voxel_index(v))] = 1;
  return make_tissue_model("mask", std::move(labels));
}

/// All links across the grid plane x = plane_x (between voxel columns plane_x - 1 and plane_x)
/// for cells whose voxel satisfies `select`.
template <typename Select>
std::vector<CellFace> links_across_x(const LinkedVolume& volume, int plane_x, Select&& select) {
  std::vector<CellFace> links;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    if (volume.cell_voxel(c).x() == plane_x - 1 && volume.neighbor(c, 1) != kNone && select(volume.cell_voxel(c)))
      links.push_back({c, 1});
  return links;
}

inline std::vector<CellFace> links_across_x(const LinkedVolume& volume, int plane_x) {
  return links_across_x(volume, plane_x, [](const Vec3i&) { return true; });
}

}  // namespace cleave::test
