#include "model_arguments.hpp"

#include <fmt/format.h>
#include <regex>

#include "cleave/core/error.hpp"
#include "cleave/io/case_file.hpp"

namespace cleave::cli {

void ModelArguments::add_to(CLI::App& cmd, bool model_required) {
  auto* opt = cmd.add_option("MODEL", model,
                             "built-in shape (cylinder, abdomen, plate), volume (.nrrd .nhdr .nii .nii.gz), "
                             "mesh (.obj .stl .ply .off) or case file (.json)");
  if (model_required) opt->required();
  else opt->capture_default_str();
  cmd.add_option("--res", resolution, "grid resolution NXxNYxNZ (built-in shapes), e.g. 126x41x84");
  cmd.add_option("--cell-size", cell_size_mm, "cell edge length in mm (volumes are resampled, meshes voxelized)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--label", labels, "segmentation labels to keep (default: every non-zero voxel)");
  cmd.add_option("--threshold", threshold, "intensity images: voxels >= this value are inside")
      ->each([this](const std::string&) { has_threshold = true; });
  cmd.add_option("--mesh-scale", mesh_scale, "multiply mesh coordinates by this factor to get mm")->check(CLI::PositiveNumber);
  cmd.add_flag("--quiet,-q", quiet, "no progress output");
}

TissueModel ModelArguments::load() const {
  ModelSourceOptions options;
  std::string source = model;
  std::map<Label, Material> materials;
  if (classify_model_source(model) == ModelSourceKind::case_file) {
    const CaseFile c = load_case_file(model);
    source = c.model_source;
    options = c.model_options;
    materials = c.materials;
  }
  if (!resolution.empty()) {
    static const std::regex kRes(R"((\d{1,6})[xX](\d{1,6})[xX](\d{1,6}))");
    std::smatch m;
    if (!std::regex_match(resolution, m, kRes))
      throw InputError(fmt::format("--res '{}': expected NXxNYxNZ with three positive integers, e.g. 63x21x42", resolution));
    options.resolution = Vec3i{std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3])};
    options.cell_size_mm.reset();
  }
  if (cell_size_mm > 0) {
    options.cell_size_mm = cell_size_mm;
    if (resolution.empty()) options.resolution.reset();
  }
  if (!labels.empty()) options.labels = labels;
  if (has_threshold) options.threshold = threshold;
  if (mesh_scale != 1.0) options.mesh_scale = mesh_scale;
  options.progress = stderr_progress(quiet);
  LabelVolume volume = load_model_source(source, options);
  report(options.progress, "building linked volume", 1.0);
  return make_tissue_model(source, std::move(volume), std::move(materials));
}

}  // namespace cleave::cli
