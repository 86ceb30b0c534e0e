#pragma once
// A tissue model: the linked volume (topology, the one place it lives), the labelled voxel grid
// it came from (labels, sub-cell surface distances), and the material of every label.
#include <map>
#include <string>

#include "cleave/fem/material.hpp"
#include "cleave/grid/label_volume.hpp"
#include "cleave/grid/linked_volume.hpp"

namespace cleave {

struct TissueModel {
  std::string source;          ///< what it was built from: "cylinder", "head.nii.gz", ...
  LabelVolume labels;          ///< the voxel labels and corner distances the volume was built from
  LinkedVolume volume;         ///< cells, links, vertices; cuts change this
  std::map<Label, Material> materials;  ///< per label; labels without an entry use Material{}

  const Material& material_of_cell(CellId c) const;
  /// Bounding box of the active cells (mm).
  std::pair<Vec3, Vec3> bounding_box_mm() const;
  /// Largest edge of the bounding box (mm): "the body's size" in tolerances.
  double size_mm() const;
};

/// Builds the linked volume from `labels` and gives every label present the default material
/// (or the named one in `materials`).
TissueModel make_tissue_model(std::string source, LabelVolume labels, std::map<Label, Material> materials = {});

}  // namespace cleave
