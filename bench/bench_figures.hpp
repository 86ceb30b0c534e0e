#pragma once
// What `cleave bench` measures for one model: per implementation (cleave itself and each peer)
// the time of every stage, its solver iterations, its agreement with cleave's result, and the
// peak memory. Plain data; bench_report.hpp turns it into JSON and tables.
//
// Stages (keys as in the JSON output):
//   vector       eigenvector interpolation: Langer and normal line fields, orthonormalization
//   value        eigenvalue interpolation after a stroke edit: Laplacian + control points +
//                equilibrium (least squares); nothing to redo when w_E = 0 (frames do not enter)
//   value_point  the same after a control-point edit (add, move, delete in turn)
//   equilibrate  making the designed stress exactly self-balanced
//   preview      one incision-preview solve: statics of the body with round incisions cut
//   step         one implicit corotational Newmark step during an ongoing cut
//   step_budget  the same steps with cleave's real-time budget (kRealTimeIterationsPerStep
//                multigrid CG iterations per step, as the studio's wound opening); its
//                relative_difference is its final displacement against cleave's solved steps
//                (peers: skipped, they solve every step)
//   update       edit-to-picture: one stroke edit -> direction + eigenvalues + preview + surface;
//                stroke 0 moves among three positions in turn (vector, value and equilibrate are
//                timed in the same edits): each edit's cells were edited before, but its design
//                is none of the last two, which every stage would answer from memory (undo)
//   update       (continued) the picture is drawn from the equilibration's provisional stress
//                when its first step already reached 1e-6 of the designed forces
//                (EquilibrationPass::picture), as the studio draws it; the equilibration's
//                completion after the picture is in update_final, not here
//   vector_drag  the eigenvector stage of a stroke dragged over fresh cells (one cell per edit)
//   update_drag  the edit-to-picture update of those edits
//   update_final, update_drag_final  the same edits until the design is final: the update
//                plus the equilibration's completion after the picture (equal to the update
//                for edits whose first step completed it)
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench_models.hpp"
#include "timing_statistics.hpp"

namespace cleave::bench {

/// Who computes: cleave's own fast path or one of the peers re-run on the same systems.
enum class Implementation {
  cleave,    ///< cleave's defaults: multigrid CG, multi-threaded, warm-started
  paper,     ///< the paper's algorithms on one thread (plain CG, CG on the normal equations)
  eigen_cg,  ///< Eigen's ConjugateGradient with incomplete Cholesky
  cholmod,   ///< SuiteSparse CHOLMOD sparse Cholesky
};

/// "cleave", "paper", "eigen_cg", "cholmod" (the JSON keys).
std::string_view implementation_key(Implementation implementation);
/// Inverse of implementation_key; throws InputError naming `option` and listing the keys.
Implementation implementation_from_key(std::string_view key, std::string_view option);

enum class Stage {
  vector,
  value,
  value_point,
  equilibrate,
  preview,
  step,
  step_budget,
  update,
  vector_drag,
  update_drag,
  update_final,
  update_drag_final
};
inline constexpr Stage kAllStages[] = {Stage::vector,      Stage::value,        Stage::value_point,  Stage::equilibrate,
                                       Stage::preview,     Stage::step,         Stage::step_budget,  Stage::update,
                                       Stage::vector_drag, Stage::update_drag,  Stage::update_final, Stage::update_drag_final};
/// "vector", "value", "value_point", "equilibrate", "preview", "step", "step_budget", "update", "vector_drag",
/// "update_drag", "update_final", "update_drag_final".
std::string_view stage_key(Stage stage);

struct StageFigures {
  TimingStatistics time;  ///< count 0 = not run (see `skipped`)
  int iterations = 0;     ///< solver iterations of one run of the stage (sum over its solves)
  /// ||x - x_cleave|| / ||x_cleave|| of the stage's result against cleave's (peers only).
  std::optional<double> relative_difference;
  std::string skipped;    ///< why the stage was not run for this implementation; empty when run
};

struct ImplementationFigures {
  Implementation implementation = Implementation::cleave;
  std::string solver;  ///< the solver's own name as it reports it
  StageFigures vector, value, value_point, equilibrate, preview, step, step_budget, update, vector_drag, update_drag,
      update_final, update_drag_final;
  double peak_mb = 0;  ///< peak resident memory while this implementation ran (MB = 1e6 bytes)

  StageFigures& stage(Stage s);
  const StageFigures& stage(Stage s) const;
};

struct ModelFigures {
  BenchModel model;
  int cells = 0;
  int vertices = 0;
  int incisions = 0;  ///< round incisions in the preview
  double design_equilibrium_weight = 0;  ///< w_E of the design stages (value, value_point)
  std::int64_t stiffness_nonzeros = 0;  ///< stored entries of K of the incised body (bandwidth estimates)
  /// Where the residual stress of the preview and the step came from: "design" (the scenario's
  /// design) or "prescribed" (uniform biaxial, when the design stages were skipped).
  std::string residual_stress = "design";
  ImplementationFigures cleave;
  std::vector<ImplementationFigures> peers;
};

}  // namespace cleave::bench
