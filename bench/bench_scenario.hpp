#pragma once
// The work every implementation repeats on one model, fixed before anything is timed so that
// all of them solve the same systems:
//   - the residual stress of the body (one Voigt tensor per cell, kPa),
//   - the round incisions of the preview (paper section 5), spread over the outer surface,
//   - the scalpel cut in progress during the dynamic steps, split into one segment per step.
//
//   BenchScenario s = make_bench_scenario(model, {.cut_segments = 7});
//
// The incisions have a radius of max(8 mm, 1.5 cells), centres at least 4 radii apart, and cut
// half the body's local thickness deep (at least one cell); a candidate whose cut would be
// refused (rim off the surface near the body's edges) is left out. The scalpel cut runs along z
// over the top of the body (across the circumferential / horizontal Langer lines), 40 % of the
// body's length, half its thickness deep.
#include <vector>

#include "cleave/cut/cut_plan.hpp"
#include "cleave/model/tissue_model.hpp"

namespace cleave::bench {

struct ScenarioOptions {
  int cut_segments = 8;  ///< pieces the scalpel cut is applied in (one per dynamic step)
};

struct BenchScenario {
  std::vector<Vec6> residual_stress_kPa;   ///< per cell of the uncut model
  CutRequests incisions;                   ///< the preview's round incisions
  std::vector<ScalpelCut> cut_segments;    ///< consecutive pieces of the ongoing scalpel cut
};

/// Throws InputError when the model has no outer surface to place incisions on.
BenchScenario make_bench_scenario(const TissueModel& model, const ScenarioOptions& options);

}  // namespace cleave::bench
