#pragma once
// Runs a case file end to end and writes its results into a folder.
#include <filesystem>

#include "cleave/core/progress.hpp"
#include "cleave/io/case_file.hpp"

namespace cleave {

struct RunResult {
  std::filesystem::path summary_file;
  std::vector<std::filesystem::path> files;  ///< every file written, for the user
};

/// Runs `case_file` and writes result.vtu, summary.json and the stage outputs into `out_dir`.
RunResult run_case(const CaseFile& case_file, const std::filesystem::path& out_dir, const ProgressFn& progress);

}  // namespace cleave
