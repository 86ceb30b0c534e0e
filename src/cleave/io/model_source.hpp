#pragma once
// Turns a model source named by the user into a labelled voxel volume:
//   a built-in shape name ("cylinder", "abdomen", "plate"),
//   a segmentation volume (.nrrd, .nhdr, .nii, .nii.gz),
//   a closed surface mesh (.obj, .stl, .ply, .off), voxelized at the cell size.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cleave/core/progress.hpp"
#include "cleave/grid/label_volume.hpp"

namespace cleave {

struct ModelSourceOptions {
  std::optional<Vec3i> resolution;     ///< grid dimensions (built-in shapes)
  std::optional<double> cell_size_mm;  ///< cell edge length (volumes are resampled to it; meshes voxelized at it)
  std::vector<int> labels;             ///< segmentation labels to keep (empty: every non-zero voxel)
  std::optional<double> threshold;     ///< intensity images: voxels >= threshold are inside (label 1)
  double mesh_scale = 1.0;             ///< meshes: multiply coordinates by this (e.g. 1800 for a height-1 mesh to mm)
  ProgressFn progress;
};

enum class ModelSourceKind { builtin, volume, mesh, case_file };

/// Which kind of source `name` is (by built-in name or file extension). Throws InputError
/// listing the accepted names and extensions when it is none of them.
ModelSourceKind classify_model_source(const std::string& name);

/// Loads or generates the labelled volume. Throws InputError naming the file and the problem.
LabelVolume load_model_source(const std::string& name, const ModelSourceOptions& options);

}  // namespace cleave
