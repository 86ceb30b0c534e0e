#include "cleave/io/model_source.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/image_label_selection.hpp"
#include "cleave/io/mesh_voxelizer.hpp"
#include "cleave/io/nifti_volume.hpp"
#include "cleave/io/nrrd_volume.hpp"
#include "cleave/io/surface_mesh_file.hpp"
#include "cleave/io/volume_resample.hpp"
#include "cleave/shapes/builtin_shapes.hpp"

namespace cleave {
namespace {

bool ends_with(std::string s, std::string_view suffix) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

LabelVolume load_volume(const std::string& name, const ModelSourceOptions& options) {
  report(options.progress, "reading " + name, 0.0);
  const bool is_nrrd = ends_with(name, ".nrrd") || ends_with(name, ".nhdr");
  const ImageVolume image = is_nrrd ? read_nrrd_volume(name) : read_nifti_volume(name);
  const std::vector<Label> labels = select_image_labels(image, {options.labels, options.threshold});
  return resample_image_labels(image, labels, {options.cell_size_mm, options.progress});
}

LabelVolume load_mesh(const std::string& name, const ModelSourceOptions& options) {
  if (!options.labels.empty() || options.threshold)
    throw InputError(fmt::format("{}: labels and thresholds select parts of volumes; a mesh has none", name));
  report(options.progress, "reading " + name, 0.0);
  const TriangleMesh mesh = read_surface_mesh(name, options.mesh_scale);
  return voxelize_surface_mesh(mesh, {options.cell_size_mm, name, options.progress});
}

}  // namespace

ModelSourceKind classify_model_source(const std::string& name) {
  if (is_builtin_shape(name)) return ModelSourceKind::builtin;
  for (const char* ext : {".nrrd", ".nhdr", ".nii", ".nii.gz"})
    if (ends_with(name, ext)) return ModelSourceKind::volume;
  for (const char* ext : {".obj", ".stl", ".ply", ".off"})
    if (ends_with(name, ext)) return ModelSourceKind::mesh;
  if (ends_with(name, ".json")) return ModelSourceKind::case_file;
  throw InputError(fmt::format("model '{}': expected a built-in shape ({}), a volume (.nrrd, .nhdr, .nii, .nii.gz), "
                               "a surface mesh (.obj, .stl, .ply, .off) or a case file (.json)",
                               name, fmt::join(builtin_shape_names(), ", ")));
}

LabelVolume load_model_source(const std::string& name, const ModelSourceOptions& options) {
  switch (classify_model_source(name)) {
    case ModelSourceKind::builtin:
      report(options.progress, "generating " + name, 0.0);
      return make_builtin_shape(name, {options.resolution, options.cell_size_mm});
    case ModelSourceKind::volume:
      return load_volume(name, options);
    case ModelSourceKind::mesh:
      return load_mesh(name, options);
    case ModelSourceKind::case_file:
      throw InputError(fmt::format("model '{}': a case file cannot be a model source inside a case", name));
  }
  throw InputError(fmt::format("model '{}': this build cannot read that format", name));
}

}  // namespace cleave
