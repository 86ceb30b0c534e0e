#include "cleave/io/model_source.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/shapes/builtin_shapes.hpp"

namespace cleave {
namespace {

bool ends_with(std::string s, std::string_view suffix) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
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
    case ModelSourceKind::mesh:
      break;
    case ModelSourceKind::case_file:
      throw InputError(fmt::format("model '{}': a case file cannot be a model source inside a case", name));
  }
  throw InputError(fmt::format("model '{}': this build cannot read that format", name));
}

}  // namespace cleave
