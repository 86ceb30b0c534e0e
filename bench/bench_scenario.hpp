#pragma once
// The work every implementation repeats on one model, fixed before anything is timed so that
// all of them solve the same systems:
//   - the stress design (paper section 7: 20 kPa along Langer's lines, 10 kPa across): two strokes
//     across the top of the body along x (the tube's circumference, the abdomen's horizontal
//     lines) at 1/3 and 2/3 of its length, and five control points on top,
//   - the edit of the edit-to-picture update: stroke 0 moved by one cell along z,
//   - a drag: stroke 0 moved one more cell towards the body's near end at every edit (fresh cells
//     each time, as a stroke dragged or drawn anew in the studio),
//   - the residual stress of the body (one Voigt tensor per cell, kPa): the design's result, or,
//     where the design cannot run (`designed_stress = false`: models above
//     `cleave bench --design-max-cells`, whose design factor would not fit in memory), a
//     prescribed stress: 20 kPa along the circumference about the z axis (the strokes' direction
//     on the tube), 10 kPa along z, 0 across the wall, in every cell,
//   - the round incisions of the preview (paper section 5), spread over the outer surface,
//   - the scalpel cut in progress during the dynamic steps, split into one segment per step.
//
//   BenchScenario s = make_bench_scenario(model, {.cut_segments = 7});
//
// The incisions (cut's place_incisions: Poisson-disk over the outer surface, seed 1) have a
// radius of max(8 mm, 1.5 cells), centres at least 4 radii apart, and cut half the body's
// thickness at its top deep (at least one cell). The scalpel cut runs along z
// over the top of the body (across the circumferential / horizontal Langer lines), 40 % of the
// body's length, half its thickness deep.
#include <vector>

#include "cleave/cut/cut_plan.hpp"
#include "cleave/model/tissue_model.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave::bench {

/// Edits of the drag (fewer where the body is too short for them).
inline constexpr int kDragEdits = 8;

struct ScenarioOptions {
  int cut_segments = 8;  ///< pieces the scalpel cut is applied in (one per dynamic step)
  /// false: no design is computed; the residual stress is the prescribed biaxial one (see above).
  bool designed_stress = true;
};

struct BenchScenario {
  StressDesign design;
  /// Stroke 0 at 1 and 2 cells towards hi.z: the update edits move stroke 0 among these and its
  /// own position in turn, so that no edit repeats one of the last two designs (which the
  /// design, the equilibration and the preview would answer from memory, as after an undo).
  std::vector<DesignStroke> edited_strokes;
  std::vector<DesignStroke> dragged_strokes;  ///< stroke 0 at 1, 2, ... cells towards lo.z (at most kDragEdits)
  std::vector<Vec6> residual_stress_kPa;   ///< per cell of the uncut model
  CutRequests incisions;                   ///< the preview's round incisions
  std::vector<ScalpelCut> cut_segments;    ///< consecutive pieces of the ongoing scalpel cut
  bool designed_stress = true;             ///< false: residual_stress_kPa is the prescribed one
};

/// The prescribed residual stress (kPa per cell): `along_kPa` along the circumference about the
/// axis parallel to z through the centre of the bounding box, `axial_kPa` along z, 0 radially
/// (cells on the axis get the axial part only).
std::vector<Vec6> prescribed_biaxial_stress(const TissueModel& model, double along_kPa, double axial_kPa);

/// Throws InputError when the model has no outer surface to place incisions on.
BenchScenario make_bench_scenario(const TissueModel& model, const ScenarioOptions& options);

}  // namespace cleave::bench
