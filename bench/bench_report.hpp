#pragma once
// `cleave bench` output: one JSON object per model, and the human-readable tables.
//
// JSON (one line per model):
//   {"model": "cylinder-42", "resolution": [42, 42, 51], "cells": 44000, "vertices": 51714,
//    "ms_vector": .., "ms_value": .., "ms_equilibrate": .., "ms_preview": .., "ms_step": ..,
//    "ms_update": .., "peak_mb": .., "iterations": {"vector": n, ...},
//    "range_ms": {"vector": [min, max], ...}, "skipped": {"vector": "why", ...},
//    "machine": {...}, "paper_2012": {"cells", "vertices", "ms_vector", "ms_value", "ms_step"},
//    "peers": {"paper": {same figures + "relative_difference": {"preview": r, ...}},
//              "eigen_cg": {...}, "cholmod": {...}}}
// Times are medians in ms; a stage that was not run has null time (and a reason in "skipped").
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench_figures.hpp"
#include "memory_bandwidth.hpp"

namespace cleave::bench {

struct MachineFigures {
  std::string cpu;                    ///< model name from /proc/cpuinfo
  int threads = 1;                    ///< TBB workers
  MemoryBandwidth bandwidth;
  bool malloc_huge_pages = false;     ///< the heap in transparent huge pages (core/allocator_tuning.hpp)
};

/// CPU model name ("model name" of /proc/cpuinfo), or "unknown".
std::string cpu_model_name();

nlohmann::json model_figures_json(const ModelFigures& figures, const MachineFigures& machine);

/// Per model and stage: cleave's median (min-max), iterations, and each peer's time.
std::string stage_table(const std::vector<ModelFigures>& models);
/// Per model and stage: cleave time / peer time, and the relative difference of the results.
std::string ratio_table(const std::vector<ModelFigures>& models);
/// The paper's Table 1 beside cleave's figures (Table 1 models only).
std::string paper_table(const std::vector<ModelFigures>& models);

}  // namespace cleave::bench
