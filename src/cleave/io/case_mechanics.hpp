#pragma once
// The case sections of the mechanics domain:
//
//   "simulation": {
//     "mode": "static" | "dynamic",                 default "static"
//     "solver": "multigrid" | "eigen-cg" | "cholmod", default "multigrid"
//     "tolerance": 1e-8,                             relative residual of each linear solve, in (0, 1)
//     "max_iterations": 2000,                        per linear solve (iterative solvers)
//     "time_step_s": 0.01, "steps": 100,             dynamic only: Newmark step and step count
//     "steps_per_frame": 10,                         dynamic: Newmark steps per displayed frame
//     "frames_every": 1,                             dynamic: write every n-th frame as frame_NNNN.vtu (0 = none)
//     "damping": {"mass_per_s": 0, "stiffness_s": 0},   Rayleigh D = alpha M + beta K
//     "fixed": "none" | "free" | {"box_mm": [[x0,y0,z0],[x1,y1,z1]]} | {"surface": "inner"}
//              | [ {"box_mm": ...}, {"surface": "inner"}, ... ],
//              "inner": every vertex on the body's inner surface (a shell's deep face, lying on
//              the body beneath; cut/body_surface.hpp), held in addition to the boxes
//     "gravity_mm_per_s2": [0, 0, -9810]              default none
//   }
//   "residual_stress": {"uniform_kPa": [xx, yy, zz, xy, xz, yz]}
//                    | {"per_label_kPa": {"1": [xx, yy, zz, xy, xz, yz], "2": [...]}}
//
// Every error is an InputError naming the file, JSON path, value and what was expected, e.g.
//   "case.json: /simulation/time_step_s is -1; expected a positive time step in s".
#include <optional>
#include <vector>

#include "cleave/io/case_file.hpp"
#include "cleave/model/tissue_model.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

enum class SimulationMode { static_equilibrium, dynamic };

/// Axis-aligned box of held vertices (reference positions, mm, inclusive).
struct FixedBox {
  Vec3 lo_mm = Vec3::Zero();
  Vec3 hi_mm = Vec3::Zero();
};

/// A whole side of the body's surface held ({"surface": "inner"}).
enum class FixedSurface { inner };

struct SimulationSettings {
  SimulationMode mode = SimulationMode::static_equilibrium;
  SolverKind solver = SolverKind::multigrid_cg;
  SolveSettings solve;
  double time_step_s = 0.01;
  int steps = 100;
  int steps_per_frame = 10;
  int frames_every = 1;
  int iterations_per_step = 0;  ///< dynamic: the real-time budget (DynamicsSettings::iterations_per_step); 0 = none
  double mass_damping_per_s = 0;
  double stiffness_damping_s = 0;
  double numerical_damping = 0.2;  ///< HHT -alpha (fem/dynamics.hpp)
  /// Generalized-alpha's spectral radius for what the step cannot resolve (0 to 1; unset: HHT).
  std::optional<double> high_frequency_radius;
  std::vector<FixedBox> fixed_boxes;  ///< empty (and no fixed_surfaces) = free body ("none" / "free")
  std::vector<FixedSurface> fixed_surfaces;
  Vec3 gravity_mm_per_s2 = Vec3::Zero();
};

/// The "simulation" section (defaults when absent). Throws InputError on bad fields.
SimulationSettings parse_simulation_settings(const CaseFile& case_file);

/// The direct "residual_stress" section as one tensor per cell of `model` (kPa), or nullopt when
/// the case has no such section. Cells whose label per_label_kPa does not list get zero stress;
/// a listed label the model does not have is refused.
std::optional<std::vector<Vec6>> parse_direct_residual_stress(const CaseFile& case_file, const TissueModel& model);

}  // namespace cleave
