#include "cleave/model/tissue_model.hpp"

#include <algorithm>
#include <limits>

namespace cleave {

const Material& TissueModel::material_of_cell(CellId c) const {
  static const Material kDefault{};
  const auto it = materials.find(volume.cell_label(c));
  return it == materials.end() ? kDefault : it->second;
}

std::pair<Vec3, Vec3> TissueModel::bounding_box_mm() const {
  Vec3i lo = Vec3i::Constant(std::numeric_limits<int>::max());
  Vec3i hi = Vec3i::Constant(std::numeric_limits<int>::min());
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    lo = lo.cwiseMin(volume.cell_voxel(c));
    hi = hi.cwiseMax(volume.cell_voxel(c));
  }
  const GridSpec& g = volume.grid();
  return {g.corner_position_mm(lo), g.corner_position_mm(hi + Vec3i::Ones())};
}

double TissueModel::size_mm() const {
  const auto [lo, hi] = bounding_box_mm();
  return (hi - lo).maxCoeff();
}

TissueModel make_tissue_model(std::string source, LabelVolume labels, std::map<Label, Material> materials) {
  TissueModel model;
  model.source = std::move(source);
  model.volume = LinkedVolume::from_labels(labels);
  for (const auto& [label, name] : labels.label_names) {
    auto [it, inserted] = materials.try_emplace(label, Material{});
    if (inserted) it->second.name = name;
  }
  model.labels = std::move(labels);
  model.materials = std::move(materials);
  return model;
}

}  // namespace cleave
