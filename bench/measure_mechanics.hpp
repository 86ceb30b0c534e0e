#pragma once
// The two solver-backed stages, timed for one implementation on copies of the uncut model:
//
//   incision preview  the round incisions are cut (not timed), the stiffness of the cut body is
//                     assembled (not timed), then the static solve K u = -T sigma with 3-2-1
//                     supports of the free plugs is timed: `repeat` solves from scratch.
//   dynamic step      a Dynamics (implicit corotational Newmark, dt = 1/60 s) starts on the body;
//                     before each step the next segment of the scalpel cut is applied and the
//                     simulation told about it (not timed); the step itself is timed. Two warm-up
//                     steps, then `repeat` timed steps; every implementation takes the same steps.
//                     Its iterations are the largest count of the timed steps. With
//                     `iterations_per_step` > 0 every step stops after that many iterations
//                     (DynamicsSettings::iterations_per_step: the real-time budget).
//
// Each returns the stage's figures and its final displacement (3 n_v, mm) so peers can be
// compared with cleave. ComputeError from a solver propagates.
#include <cstdint>

#include "bench_figures.hpp"
#include "bench_scenario.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave::bench {

inline constexpr double kBenchTimeStep_s = 1.0 / 60.0;
inline constexpr double kBenchMassDamping_per_s = 2.0;
inline constexpr int kWarmUpSteps = 2;

struct MechanicsOutcome {
  StageFigures figures;
  Eigen::VectorXd displacement_mm;  ///< final displacement, 3 n_v
  std::string solver;               ///< the solver's name
  std::int64_t matrix_nonzeros = 0; ///< stored entries of the stiffness of the cut body
};

MechanicsOutcome measure_incision_preview(const TissueModel& uncut, const BenchScenario& scenario,
                                          Implementation implementation, int repeat);

MechanicsOutcome measure_dynamic_step(const TissueModel& uncut, const BenchScenario& scenario,
                                      Implementation implementation, int repeat, int iterations_per_step = 0);

}  // namespace cleave::bench
