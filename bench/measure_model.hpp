#pragma once
// One model of `cleave bench`, end to end: build it at its resolution, fix the scenario, run
// every stage for cleave and then for each peer on the same systems, compare each peer's results
// with cleave's, and record the peak memory of each implementation.
//
//   BenchOptions options;                       // repeat 5, peers paper + eigen_cg + cholmod
//   ModelFigures f = measure_model(table1_models()[1], options, progress);
//
// Peers are skipped (with the reason recorded) on models above `peer_max_cells`, where a
// single-threaded or direct solver would take minutes and tens of GB. On models above
// `design_max_cells` the design stages (and the edit-to-picture update, which contains them) are
// skipped before anything is allocated for them, with the reason and an estimate of the memory
// their sparse Cholesky factors would need; the preview and the step then run on the prescribed
// biaxial residual stress (bench_scenario.hpp), so the solver stages are measured at any size. Progress goes to
// `progress` (stage name, fraction of this model done). Errors: InputError for a bad scenario,
// ComputeError when a solver fails.
#include <optional>
#include <vector>

#include "bench_figures.hpp"
#include "cleave/core/progress.hpp"

namespace cleave::bench {

struct BenchOptions {
  int repeat = 5;  ///< timed runs per stage (medians over these)
  std::vector<Implementation> peers = {Implementation::paper, Implementation::eigen_cg, Implementation::cholmod};
  int peer_max_cells = 400'000;  ///< peers are skipped on larger models
  /// Design stages are skipped on larger models (their factors' fill-in: 4.2 GB at 44k cells,
  /// CHOLMOD's int-indexed supernodal analysis overflowed at 100k).
  int design_max_cells = 60'000;
  /// w_E of the design stages (eq. 6 rows in the eigenvalue least squares); unset = the default design's.
  std::optional<double> design_equilibrium_weight;
};

/// Memory (GB) the design stages' sparse Cholesky factors would need on a model of `cells` cells:
/// the 4.2 GB peak measured at 44,064 cells, scaled as cells^(4/3) (nested-dissection fill-in on
/// 3-D grids). An extrapolation for the skip note, not a measurement.
double design_memory_estimate_gb(int cells);

ModelFigures measure_model(const BenchModel& model, const BenchOptions& options, const ProgressFn& progress);

}  // namespace cleave::bench
