#pragma once
// Small models for the fem tests: boxes of cubic cells built straight from a label volume.
#include <map>

#include "cleave/model/tissue_model.hpp"

namespace cleave::test {

/// A solid box of nx x ny x nz cells of edge h (mm) with its corner at the origin, label 1,
/// material E (kPa), nu, density 1000 kg/m^3.
/// `label_of_voxel` may give other labels (materials from `extra_materials`, default otherwise).
using LabelOfVoxel = Label (*)(const Vec3i&);
inline TissueModel make_box_model(const Vec3i& cells, double h_mm, double youngs_modulus_kPa = 80.0,
                                  double poisson_ratio = 0.4, LabelOfVoxel label_of_voxel = nullptr,
                                  std::map<Label, Material> extra_materials = {}) {
  LabelVolume labels;
  labels.grid.dims = cells;
  labels.grid.cell_size_mm = h_mm;
  labels.grid.origin_mm = Vec3::Zero();
  labels.labels.assign(static_cast<std::size_t>(labels.grid.voxel_count()), Label{1});
  if (label_of_voxel != nullptr)
    for (int z = 0; z < cells.z(); ++z)
      for (int y = 0; y < cells.y(); ++y)
        for (int x = 0; x < cells.x(); ++x)
          labels.labels[static_cast<std::size_t>(labels.grid.voxel_index({x, y, z}))] = label_of_voxel({x, y, z});
  Material m;
  m.youngs_modulus_kPa = youngs_modulus_kPa;
  m.poisson_ratio = poisson_ratio;
  extra_materials[Label{1}] = m;
  return make_tissue_model("box", std::move(labels), std::move(extra_materials));
}

/// Uncut faces between the cells for which `inside` holds and the others, as cut_links input.
template <typename Inside>
std::vector<CellFace> faces_between(const LinkedVolume& volume, Inside&& inside) {
  std::vector<CellFace> faces;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    if (!inside(c)) continue;
    for (Face f = 0; f < kFaceCount; ++f) {
      const CellId n = volume.neighbor(c, f);
      if (n != kNone && !inside(n)) faces.push_back({c, f});
    }
  }
  return faces;
}

}  // namespace cleave::test
