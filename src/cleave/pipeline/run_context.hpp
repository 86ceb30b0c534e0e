#pragma once
// The state of one batch run (`cleave run CASE --out DIR`) as it passes through the stages:
//   model -> residual stress (direct or designed) -> cuts and incisions -> mechanics
//         -> measurements -> render surface -> result.vtu + summary.json
// Each stage is a free function in its own file (stage_*.cpp) that reads the case section it
// owns and adds fields, summary entries and files.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "cleave/core/progress.hpp"
#include "cleave/io/case_file.hpp"
#include "cleave/io/vtu_writer.hpp"
#include "cleave/model/tissue_model.hpp"

namespace cleave {

struct RunContext {
  const CaseFile& case_file;
  std::filesystem::path out_dir;
  ProgressFn progress;

  TissueModel model;
  std::vector<Vec6> residual_stress_kPa;  ///< per cell (Voigt); empty = stress free
  std::vector<Vec3> displacement_mm;      ///< per vertex of the (cut) linked volume; empty = at rest
  VolumeFields fields;                    ///< arrays written to result.vtu (units in docs/case-format.md)
  std::vector<PvdEntry> frames;           ///< time series written to frames.pvd
  nlohmann::json summary = nlohmann::json::object();  ///< written to summary.json
  /// Cut-domain state the cut stage leaves for the measure stage (incisions, scalpel paths).
  nlohmann::json cut_state = nlohmann::json::object();
  /// Removed plugs the cut stage leaves for the mechanics stage: hidden, held in place.
  std::vector<CellId> removed_cells;

  /// Adds `seconds` under summary["timings_s"][stage].
  void record_time(const std::string& stage, double seconds) { summary["timings_s"][stage] = seconds; }
};

}  // namespace cleave
