#pragma once
// Options shared by commands that take a MODEL argument (info, studio, bench):
// MODEL is a built-in name, a volume, a mesh or a case file.
#include <CLI/CLI.hpp>
#include <string>

#include "cleave/model/tissue_model.hpp"
#include "progress_bar.hpp"

namespace cleave::cli {

struct ModelArguments {
  std::string model = "abdomen";
  std::string resolution;  ///< "NXxNYxNZ"
  double cell_size_mm = 0;
  std::vector<int> labels;
  double threshold = 0;
  bool has_threshold = false;
  double mesh_scale = 1.0;
  bool quiet = false;

  /// Adds MODEL and --res, --cell-size, --label, --threshold, --mesh-scale, --quiet to `cmd`.
  void add_to(CLI::App& cmd, bool model_required);
  /// Loads the model (a case file's model section when MODEL ends in .json).
  TissueModel load() const;
};

}  // namespace cleave::cli
