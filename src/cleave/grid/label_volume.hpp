#pragma once
// A labelled voxel grid: the common form every model source (built-in shape, NRRD/NIfTI mask,
// voxelized surface mesh) is turned into before the linked volume is built from it.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cleave/grid/grid_spec.hpp"

namespace cleave {

/// Tissue label of a voxel; 0 means outside the body.
using Label = std::uint8_t;

struct LabelVolume {
  GridSpec grid;
  std::vector<Label> labels;  ///< one per voxel, indexed by grid.voxel_index; 0 = outside
  /// Optional signed distance to the body surface at every grid corner (mm, negative inside),
  /// indexed by grid.corner_index. When present the render surface places its vertices at the
  /// zero crossing (sub-cell accuracy); when empty it falls back to the voxel faces.
  std::vector<float> corner_distance_mm;
  std::map<Label, std::string> label_names;  ///< e.g. {1: "skin", 2: "fat", 3: "muscle"}

  Label at(const Vec3i& v) const { return grid.contains_voxel(v) ? labels[static_cast<size_t>(grid.voxel_index(v))] : Label{0}; }
  bool has_distance() const { return !corner_distance_mm.empty(); }
  std::int64_t inside_count() const;
};

/// Allocates an all-outside volume for `grid` after checking that it fits in memory.
LabelVolume make_empty_label_volume(const GridSpec& grid, bool with_distance);

}  // namespace cleave
